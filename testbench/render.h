// oprt render: the timed model. Options are resolved in the order built-in defaults <
// architecture file < command-line flags; then the scene's geometry, spheres and unit
// assignment are built, and the SystemC testbench (testbench.h) runs the frames.
#pragma once

#include "arch/arch.h"
#include "options.h"
#include "scene/load.h"

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

namespace oprt {

struct RenderOptions {
  std::string scene, arch_file, frames, resolution, out = "out", vcd, timeline;
  std::optional<std::string> trace_frames, trace_window, trace_units, trace_signals;  // what the traces hold
  std::optional<std::size_t> trace_buffer;  // changes the waveform writer may hold
  std::optional<std::string> max_memory;    // --max-memory: a byte count
  std::optional<int> ius, subdivide, depth;
  std::optional<std::string> level, quantum, balance, locality, replicate, accel, top, route, kernel, precision, sram, iu;
  std::optional<std::string> sample, sample_fifos;  // --sample 1/N, --sample-fifos scaled | kept
  std::optional<std::uint64_t> seed;                // --seed: which pixel of each block
  std::string tech;  // technology table; empty: the built-in 65 nm one
  bool progress = true;  // on a terminal only
  bool check = false;    // --check: every check a render makes, then stop (scripts/sweep)
  std::string split;     // "": the architecture file's, else the format's default
  std::optional<std::size_t> max_object_triangles;
  LoadOptions load;
};

int run_render(const RenderOptions& o);

// oprt batch (batch_cmd.cpp): the loaded scenes and the built spheres and BVHs that the renders
// of one process share. A render given a cache takes its scene and geometry from it when an
// earlier one loaded and built them with the same options (the geometry copied: a deforming
// scene changes its copy), and leaves what it loads and builds there.
struct RenderCache;
std::shared_ptr<RenderCache> make_render_cache();
int run_render(const RenderOptions& o, RenderCache* cache);

// Defaults < file < flags. Throws InputError on a bad value.
Arch resolve_arch(const RenderOptions& o);

}  // namespace oprt
