// The SystemC testbench of `oprt render`: one thread that, per frame, evaluates the scene's
// animation, sends the frame's matrices to the engine's GPP, waits for the frame to
// complete, and collects the image, the per-unit cycles and the trace.
#pragma once

#include "balance/assign.h"
#include "hw/engine.h"
#include "options.h"
#include "run_cost.h"
#include "stats.h"
#include "trace_select.h"

#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <string>

namespace oprt {

struct RenderJob {
  const Scene* scene = nullptr;
  Arch arch;
  FrameRange frames;
  int width = 0, height = 0;
  std::string out_dir, vcd_path, timeline_path;
  TraceSelection trace;  // what --vcd and --timeline hold
  std::size_t trace_budget = VcdWriter::kDefaultBudget;  // changes the waveform writer may buffer
  Assignment assignment;
  bool progress = false;
  nlohmann::json header;  // resolved configuration, for stats.json
  std::shared_ptr<RunCost> cost;  // area and energy (a technology table)
  int completed = 0;      // frames written
  std::exception_ptr error;  // what stopped the simulation thread, if anything
  bool write_files = true;   // frames and stats into out_dir
  bool keep_results = false; // keep every frame's image and stats in memory (tests)
  std::vector<FrameStats> results;
  std::vector<FrameImage> images;
};

// Build the engine for `job` and run every frame; returns when done. Must be called where
// SystemC may elaborate (sc_main). Throws on failure.
// The geometry's deforming objects (if any) are updated before each frame.
template <typename T>
void simulate(RenderJob& job, SceneGeometry<T>& geometry);

extern template void simulate<float>(RenderJob&, SceneGeometry<float>&);
extern template void simulate<double>(RenderJob&, SceneGeometry<double>&);

}  // namespace oprt
