// The oprt subcommands (main.cpp parses the command line and dispatches here).
#pragma once

#include "scene/load.h"

#include <cstddef>
#include <optional>
#include <string>

namespace oprt {

struct CommonOptions {
  std::string scene;
  std::string frames;
  std::string resolution;
  std::string out = "out";
  std::string precision = "float";
  std::string accel = "brute";
  std::string kernel = "moller";
  int subdivide = 1;
  std::optional<int> depth;  // --depth: Whitted's recursion bound (else the scene's)
  std::string split;  // "count" | "extent"; "": the format's default (balance/spheres.h)
  std::optional<std::size_t> max_object_triangles;
  bool schedules = false;
  std::optional<std::string> max_memory;  // --max-memory: a byte count
  LoadOptions load;
};

struct RenderOptions;
// `arch`: the architecture options info takes (--arch, --ius, --balance, --locality,
// --accel, --subdivide), resolved as render resolves them.
int run_info(const CommonOptions& o, const RenderOptions& arch);
int run_reference(const CommonOptions& o);
// Prints the difference of IMAGE from REFERENCE as JSON.
int run_compare(const std::string& image, const std::string& reference);

}  // namespace oprt
