// The command line's value syntaxes built from numbers (--frames, --resolution), shared by the
// oprt subcommands; each number is read by base/numbers.h. Bad values throw InputError
// naming the option.
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
// The same without a scene: the range as written (frame numbers up to 2^31 - 1).
FrameRange parse_frame_range(const std::string& text, const std::string& option);
// "WxH" (1 to 16384 each); empty = the scene's.
void parse_resolution(const std::string& text, int& width, int& height);

// "0.5": --locality, a number in [0, 1]. Throws InputError naming the option.
double parse_locality(const std::string& text);

// The loader's options under a split rule. A BART group is split by count into objects of
// at most --max-object-triangles: by default 4,096 under `count` (the rule before split by
// extent), none under `extent` (groups stay whole and the spheres are split by extent).
LoadOptions load_options_for(LoadOptions load, std::optional<std::size_t> max_object_triangles, ObjectSplit split);

}  // namespace oprt
