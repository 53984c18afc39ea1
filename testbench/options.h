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
// "65536", "64K", "64KB", "4M" (K = 1024, M = 1024 K); 0 means no limit. Throws InputError naming `what`.
std::uint64_t parse_bytes(const std::string& text, const std::string& what);

}  // namespace oprt
