// Sampled simulation (--sample F, --seed S): the full frame's figures estimated from a frame
// that traced one pixel in each block of 1/F (sample/pixel_sample.h), each with a 95 %
// interval from the sample's own variance, and the reasons the interval is not to be
// trusted where there are any. docs/timing-levels.md, "Sampled simulation", has the argument;
// in short:
//  - what the trace counts per pixel (each unit's work and bytes, the rays, the GPP's work,
//    the bus traffic: timing/sample_figures.h) is a Horvitz-Thompson total, its variance by
//    collapsed strata (sample/strata.h);
//  - what only the timed model knows (a pipelined unit's occupied cycles, stalls, cache
//    counts, bus occupancy) is expanded by the ratio to its proxy among those;
//  - the frame is its start (measured: the sample does the full frame's) and a body the
//    sampled rays compress: the body is eta times the demand of its busiest resource (each
//    unit, the bus, the GPP), eta measured on the sample; the maximum's upward bias and its
//    interval come from a seeded bootstrap over the resources' joint estimates;
//  - the energy is the cost model's on the frame's counts expanded (the frame's start and its
//    loads kept, the design sized as the full frame would size it), its interval from the
//    dynamic energy's per-pixel share drawn with the makespan's.
// The ray FIFOs a sampled run times hold the same stretch of the screen as the full run's
// (sampled_fifo_depth), unless --sample-fifos kept.
#pragma once

#include "balance/policy_driver.h"
#include "run_cost.h"
#include "sample/pixel_sample.h"
#include "stats.h"
#include "timing/unit_run.h"

#include <array>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oprt {

// The depth a sampled run times for a ray FIFO of `depth` (0: unbounded, kept): the full run's
// FIFO of d <= W rays holds d pixels of a row, d / bw sampled rays; one of d >= W bh holds d / W
// rows, d F sampled rays (a sample row stands for bh of the frame's); between, one sample row
// (W / bw). Rounded, at least 1.
int sampled_fifo_depth(int depth, const PixelSample& s);

class SampleEstimator {
 public:
  // `cost`: the run's; the estimator keeps a copy whose design grows with the expanded frames.
  SampleEstimator(const Arch& arch, std::shared_ptr<const PixelSample> sample, int fifo_depth_timed, const RunCost& cost);

  // Frame `fs` (the sample's own figures) and its run's per-pixel figures -> the estimate;
  // says on stderr, once per run and reason, where the interval is not to be trusted.
  SampleEstimate estimate(const timing::FrameRun& run, const FrameStats& fs);
  // What the feedback policy reads of the frame before, expanded to the full frame.
  MeasuredFrame expanded(MeasuredFrame m) const;

 private:
  const Arch& arch_;
  std::shared_ptr<const PixelSample> sample_;
  int fifo_depth_timed_;
  RunCost cost_;
  double expansion_ = 1;  // the last frame's: full rays over sampled rays
  int frames_ = 0;
  std::set<std::string> warned_;
  void warn(const std::vector<std::string>& flags);
};

}  // namespace oprt
