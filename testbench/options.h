// Parsing of the command line's value syntaxes (--frames, --resolution, --quantum), shared by
// the oprt subcommands. Bad values throw InputError naming the option.
#pragma once

#include "scene/scene.h"

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

}  // namespace oprt
