// What one `oprt render` run asks for and what it gives back: the scene, the architecture,
// the frames and outputs, and (for tests) every frame's image and statistics. Every level
// takes it: the SystemC testbench (testbench.h) and the analytic level, and frame_output.h
// writes what it says.
#pragma once

#include "balance/assign.h"
#include "options.h"
#include "run_cost.h"
#include "sample_estimate.h"
#include "stats.h"
#include "trace/vcd_writer.h"
#include "trace_select.h"

#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace oprt {

struct RenderJob {
  const Scene* scene = nullptr;
  Arch arch;
  Arch engine_arch;  // what the engine times: `arch`, with --sample its ray FIFOs scaled (sample_estimate.h)
  FrameRange frames;
  int width = 0, height = 0;
  std::string out_dir, vcd_path, timeline_path;
  TraceSelection trace;  // what --vcd and --timeline hold
  std::size_t trace_budget = VcdWriter::kDefaultBudget;  // changes the waveform writer may buffer
  Assignment assignment;
  bool progress = false;
  nlohmann::json header;  // resolved configuration, for stats.json
  std::shared_ptr<RunCost> cost;  // area and energy (a technology table)
  std::shared_ptr<const PixelSample> sample;    // --sample: the pixels each frame traces (null: every one)
  std::shared_ptr<SampleEstimator> estimator;   // --sample: the full frame's figures from the sample's
  int completed = 0;      // frames written
  std::exception_ptr error;  // what stopped the simulation thread, if anything
  bool write_files = true;   // frames and stats into out_dir
  bool keep_results = false; // keep every frame's image and stats in memory (tests)
  std::vector<FrameStats> results;
  std::vector<FrameImage> images;
};

}  // namespace oprt
