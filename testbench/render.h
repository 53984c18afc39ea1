// oprt render: the timed model. Options are resolved in the order built-in defaults <
// architecture file < command-line flags; then the scene's geometry, spheres and unit
// assignment are built, and the SystemC testbench (testbench.h) runs the frames.
#pragma once

#include "hw/arch.h"
#include "options.h"
#include "scene/load.h"

#include <optional>
#include <string>

namespace oprt {

struct RenderOptions {
  std::string scene, arch_file, frames, resolution, out = "out", vcd;
  std::optional<int> ius, subdivide;
  std::optional<std::string> level, quantum, balance, accel, kernel, precision, iu;
  std::string tech;  // technology table; empty: the built-in 65 nm one
  bool progress = true;  // on a terminal only
  LoadOptions load;
};

int run_render(const RenderOptions& o);

// Defaults < file < flags. Throws InputError on a bad value.
Arch resolve_arch(const RenderOptions& o);

}  // namespace oprt
