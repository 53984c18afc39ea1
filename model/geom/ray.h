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

// What a ray is for. A shadow ray asks whether anything lies before its light (any hit); the
// others ask for the nearest hit: the camera's primary ray, and Whitted's secondary rays, a
// mirror reflection and a refraction, issued where a hit's material reflects or transmits.
enum class RayKind : std::uint8_t { primary = 0, shadow = 1, reflection = 2, refraction = 3 };
constexpr int kRayKinds = 4;
constexpr const char* kRayKindNames[kRayKinds] = {"primary", "shadow", "reflection", "refraction"};
constexpr bool seeks_nearest(RayKind k) { return k != RayKind::shadow; }
// The ceiling of Whitted's recursion bound (a ray's depth is kept in a byte; 16 bounces at
// the weights scenes publish leave nothing visible).
constexpr int kMaxDepth = 16;

}  // namespace oprt
