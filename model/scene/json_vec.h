// A JSON value of three numbers as a vector ([x, y, z]): the scene readers' colours,
// positions and directions (base/json_in.h reads the numbers; geometry is the scene's).
#pragma once

#include "base/json_in.h"
#include "geom/vec.h"

#include <string>

namespace oprt {

inline Vec3d vec3(const JsonIn& j) {
  const std::array<double, 3> a = j.array3();
  return {a[0], a[1], a[2]};
}

// An optional member with a default.
inline Vec3d vec3_or(const JsonIn& j, const std::string& key, const Vec3d& def) {
  auto v = j.find(key);
  return v ? vec3(*v) : def;
}

}  // namespace oprt
