#include "options.h"

#include "scene/error.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

namespace oprt {

namespace {
bool parse_int(const std::string& s, long long& out) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  out = std::stoll(s);
  return true;
}
}  // namespace

FrameRange parse_frames(const std::string& text, const Scene& scene) {
  FrameRange r{0, scene.frame_count - 1};
  if (text.empty()) return r;
  const auto colon = text.find(':');
  long long a, b;
  if (colon == std::string::npos) {
    if (!parse_int(text, a)) throw InputError("--frames", text, "expected N or A:B (non-negative integers)");
    b = a;
  } else if (!parse_int(text.substr(0, colon), a) || !parse_int(text.substr(colon + 1), b)) {
    throw InputError("--frames", text, "expected N or A:B (non-negative integers)");
  }
  if (a > b) throw InputError("--frames", text, "first frame is after the last");
  if (b >= scene.frame_count)
    throw InputError("--frames", text,
                     "scene has frames 0:" + std::to_string(scene.frame_count - 1) + " only");
  r.first = static_cast<int>(a);
  r.last = static_cast<int>(b);
  return r;
}

void parse_resolution(const std::string& text, int& width, int& height) {
  if (text.empty()) return;
  const auto x = text.find('x');
  long long w, h;
  if (x == std::string::npos || !parse_int(text.substr(0, x), w) || !parse_int(text.substr(x + 1), h) ||
      w < 1 || h < 1 || w > 16384 || h > 16384)
    throw InputError("--resolution", text, "expected WxH with 1 <= W, H <= 16384");
  width = static_cast<int>(w);
  height = static_cast<int>(h);
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

std::uint64_t parse_bytes(const std::string& text, const std::string& what) {
  std::size_t digits = 0;
  while (digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits]))) ++digits;
  std::string unit = text.substr(digits);
  std::uint64_t scale = 1;
  if (unit == "K" || unit == "KB" || unit == "k" || unit == "kB") scale = 1024;
  else if (unit == "M" || unit == "MB") scale = 1024 * 1024;
  else if (!unit.empty()) digits = 0;
  long long n;
  if (digits == 0 || !parse_int(text.substr(0, digits), n) || static_cast<std::uint64_t>(n) > (std::uint64_t{1} << 40) / scale)
    throw InputError(what, text, "expected a byte count such as 65536, 64K or 4M (at most 1 TiB; 0: no limit)");
  return static_cast<std::uint64_t>(n) * scale;
}

}  // namespace oprt
