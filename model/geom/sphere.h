// Bounding spheres and the IU's ray-sphere test.
#pragma once

#include "geom/ray.h"

namespace oprt {

template <typename T>
struct Sphere {
  Vec3<T> c;
  T r = 0;
};

// Does the ray's line pass through the sphere, in front of the origin or with the origin
// inside? The test only culls: a sphere it accepts costs a transform and the sphere's
// triangles, so it may accept too much but must never reject a sphere the ray enters.
// World rays have unit d.
//
// Numerics (Haines, Guenther, Akenine-Moller, Ray Tracing Gems ch. 7). The textbook
// discriminant |f|^2 - (f.d)^2, with f = o - c, cancels catastrophically for a small
// sphere far away: at |f| = 1e4 in float both terms are ~1e8 with an absolute error of
// ~10, so any sphere of radius below ~3 is missed or found at random. Forming the
// perpendicular vector l = f - (f.d) d first and squaring it has a relative error of a few
// ulps of |l|^2 itself, so r^2 - |l|^2 keeps its sign whenever the ray clears or enters
// the sphere by more than a few ulps of r (and sphere radii carry a margin larger than that,
// see frame_setup).
//
// Cost: 10 multiplies and 12 adds, 14 cycles on one adder and one multiplier (see
// arch/cycle_schedule.cpp); the paper's Table 1 charges 9 (the textbook form schedules in 10).
template <typename T>
inline bool hit_sphere(const Ray<T>& ray, const Sphere<T>& s) {
  const Vec3<T> f = ray.o - s.c;
  const T b = dot3(f, ray.d);  // distance of the closest point along d, negated
  const Vec3<T> l = f - b * ray.d;
  const T r2 = s.r * s.r;
  if (dot3(l, l) > r2) return false;      // the line misses
  return b <= 0 || dot3(f, f) <= r2;      // centre ahead, or origin inside
}

// The paper's form (Table 1: 9 cycles), kept for comparison in tests and benchmarks.
template <typename T>
inline bool hit_sphere_textbook(const Ray<T>& ray, const Sphere<T>& s) {
  const Vec3<T> L = s.c - ray.o;
  const T tca = dot3(L, ray.d);
  const T ll = dot3(L, L);
  const T r2 = s.r * s.r;
  if (ll - tca * tca > r2) return false;
  return tca >= 0 || ll <= r2;
}

}  // namespace oprt
