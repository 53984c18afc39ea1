// What a render measures, per frame and per unit, and its files: stats.json (the resolved
// scene and architecture, a summary, and per frame the per-unit cycle breakdown) and
// stats.csv (one row per frame and unit). Field names are relied upon by scripts/.
#pragma once

#include "arch/arch.h"
#include "balance/replicate.h"
#include "timing/cache.h"
#include "cost/cost_model.h"
#include "timing/pipeline_timing.h"
#include "ref/work.h"
#include "timing/unit_run.h"
#include "ref/work.h"
#include "frame_log.h"

#include <array>
#include <fstream>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oprt {

// A unit's figures (timing/unit_run.h UnitRun), and what the run adds: its place in the
// assignment and its sizes.
struct UnitFrameStats : timing::UnitRun {
  int id = 0;
  std::vector<std::uint32_t> spheres;
  std::uint64_t primitives = 0;
  std::uint64_t idle = 0;
  std::uint64_t memory_capacity_bytes = 0;  // the geometry its assignment holds
  std::uint64_t config_bytes = 0;           // its configuration registers written this frame

  // Serial: the cycles it computed. Pipelined: the cycles it held at least one ray (its
  // stages work side by side, so their issue cycles can add up to more than the makespan).
  std::uint64_t busy_cycles() const { return pipeline ? pipeline->occupied : cycles.busy(); }
};

// --sample: the full frame's figures estimated from the sample's (sample_estimate.h), each
// with its 95 % interval; the frame's other figures stay the sample's own.
struct SampleEstimate {
  double makespan = 0, frame_time_s = 0;
  std::array<double, 2> makespan_interval{}, frame_time_interval{};
  std::optional<double> energy;
  std::array<double, 2> energy_interval{};
  bool trusted = true;
  std::vector<std::string> flags;
  nlohmann::json json;  // the frame's "sample" in stats.json
};

// A frame's figures (timing/unit_run.h FrameFigures), and what the run adds.
struct FrameStats : timing::FrameFigures {
  int frame = 0;
  double wall_s = 0;
  // --replicate: the copies (sphere, its units) and the bytes the copies beyond the first take.
  bool replicating = false;
  std::vector<Replica> replicas;
  std::uint64_t replica_bytes = 0, geometry_bytes = 0;
  std::uint64_t image_hash = 0;
  std::vector<UnitFrameStats> units;
  std::vector<std::uint64_t> sphere_cycles;  // per sphere: busy cycles spent on it (whichever unit)
  std::vector<std::array<std::uint64_t, kRayKinds>> sphere_entries;  // per sphere: rays entering it, by kind
  double frame_time_s = 0;      // the makespan at the architecture's clock
  std::optional<Cost> energy;   // with a technology table (--tech)
  // Pipelined units: per stage its initiation interval and latency (the same for every unit).
  std::optional<timing::PipelineConfig> pipeline;
  std::optional<SampleEstimate> sample;  // --sample

  std::uint64_t busy() const;
  double fanout_mean() const;
  std::uint64_t fanout_max() const;
  // Sum of busy cycles / (units x makespan).
  double efficiency() const;
  double idle_fraction() const;
};

// stats.json and stats.csv. Each frame's row is appended to stats.csv's temporary file and its
// JSON to stats.json's spool (frame_log.h) as it completes; finish() writes both under their
// final names. Time and memory per frame stay flat however long the run. A run that is
// stopped (SIGINT, SIGTERM) or fails after its first frame still gets both files, listing the
// frames it completed (the destructor finishes what finish() was not called for); one killed
// outright leaves only hidden temporaries.
// The work counters as stats.json and reference.json write them.
nlohmann::json work_json(const WorkCounts& w);

class StatsWriter {
 public:
  StatsWriter(std::string dir, nlohmann::json header);
  ~StatsWriter();
  StatsWriter(const StatsWriter&) = delete;
  StatsWriter& operator=(const StatsWriter&) = delete;
  void add(const FrameStats& f);
  // The run's area (a technology table): kept in the header, its total in every CSV row.
  void set_area(const Cost& area);
  void finish();

 private:
  std::string dir_, csv_tmp_;
  nlohmann::json doc_;
  FrameLog json_;
  std::ofstream csv_;
  std::optional<double> area_total_;
  // The summary's running sums.
  std::size_t frames_ = 0;
  double wall_ = 0, efficiency_ = 0, idle_ = 0, energy_ = 0, frame_time_ = 0;
  std::uint64_t makespan_ = 0, rays_ = 0, busy_ = 0, load_bytes_ = 0, load_cycles_ = 0, refit_cycles_ = 0;
  bool energy_known_ = false;
  bool finished_ = false;
  nlohmann::json sample_;  // --sample: the summary's estimates
  void add_sample(const SampleEstimate& e);
};

nlohmann::json to_json(const FrameStats& f);

}  // namespace oprt
