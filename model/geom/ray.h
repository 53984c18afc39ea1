// A ray o + t d, t in (0, tmax). World rays have a unit direction (so t is a Euclidean
// distance: Z of the image and the light distance of a shadow ray); rays carried into an
// object's local frame keep the transformed, unnormalised direction so that t means the
// same point in both frames (see affine.h).
#pragma once

#include "geom/vec.h"

namespace oprt {

template <typename T>
struct Ray {
  Vec3<T> o;
  Vec3<T> d;
  T tmax = kInf<T>;
};

enum class RayKind : std::uint8_t { primary = 0, shadow = 1 };
constexpr int kRayKinds = 2;

}  // namespace oprt
