// Parsing of the command line's value syntaxes (--frames, --resolution, --quantum), shared by
// the oprt subcommands. Bad values throw InputError naming the option.
#pragma once

#include "balance/spheres.h"
#include "scene/load.h"
#include "scene/scene.h"

#include <cstddef>
#include <optional>
#include <string>

namespace oprt {

struct FrameRange {
  int first = 0, last = 0;  // inclusive
  int count() const { return last - first + 1; }
};

// "N" (one frame) or "A:B" (A to B inclusive); empty = every frame of the scene.
FrameRange parse_frames(const std::string& text, const Scene& scene);
// "WxH"; empty = the scene's own.
void parse_resolution(const std::string& text, int& width, int& height);
// "65536", "64K", "64KB", "4M" (K = 1024, M = 1024 K); 0 means no limit. Throws InputError naming `what`.
std::uint64_t parse_bytes(const std::string& text, const std::string& what);

// "0.5": --locality, a number in [0, 1]. Throws InputError naming the option.
double parse_locality(const std::string& text);

// The loader's options under a split rule. A BART group is split by count into objects of
// at most --max-object-triangles: by default 4,096 under `count` (the rule before split by
// extent), none under `extent` (groups stay whole and the spheres are split by extent).
LoadOptions load_options_for(LoadOptions load, std::optional<std::size_t> max_object_triangles, ObjectSplit split);

}  // namespace oprt
