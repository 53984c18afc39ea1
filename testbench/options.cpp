#include "options.h"

#include "base/error.h"
#include "base/numbers.h"

#include <cctype>
#include <climits>
#include <cmath>
#include <cstdlib>

namespace oprt {

FrameRange parse_frame_range(const std::string& text, const std::string& option) {
  const auto colon = text.find(':');
  const NumberSource at{option, text};
  FrameRange r;
  if (colon == std::string::npos) {
    r.first = r.last = static_cast<int>(parse_count(text, 0, INT_MAX, at));
  } else {
    r.first = static_cast<int>(parse_count(text.substr(0, colon), 0, INT_MAX, at));
    r.last = static_cast<int>(parse_count(text.substr(colon + 1), 0, INT_MAX, at));
  }
  if (r.first > r.last) throw InputError(option, text, "first frame is after the last");
  return r;
}

FrameRange parse_frames(const std::string& text, const Scene& scene) {
  if (text.empty()) return {0, scene.frame_count - 1};
  const FrameRange r = parse_frame_range(text, "--frames");
  if (r.last >= scene.frame_count)
    throw InputError("--frames", text, "scene has frames 0:" + std::to_string(scene.frame_count - 1) + " only");
  return r;
}

void parse_resolution(const std::string& text, int& width, int& height) {
  if (text.empty()) return;
  const auto x = text.find('x');
  if (x == std::string::npos) throw InputError("--resolution", text, "expected WxH, such as 256x256");
  width = static_cast<int>(parse_count(text.substr(0, x), 1, 16384, {"--resolution", text}));
  height = static_cast<int>(parse_count(text.substr(x + 1), 1, 16384, {"--resolution", text}));
}

double parse_locality(const std::string& text) {
  const char* s = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (text.empty() || *end != '\0' || !(v >= 0 && v <= 1))
    throw InputError("--locality", text, "expected a number from 0 (balance first) to 1 (tight unit bounds first)");
  return v;
}

LoadOptions load_options_for(LoadOptions load, std::optional<std::size_t> max_object_triangles, ObjectSplit split) {
  load.aff.max_object_triangles = max_object_triangles ? *max_object_triangles
                                  : split == ObjectSplit::count ? AffOptions{}.max_object_triangles
                                                                : 0;
  return load;
}

}  // namespace oprt
