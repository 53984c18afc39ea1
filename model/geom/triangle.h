// Ray-triangle intersection, Moller-Trumbore, in the form the intersection unit runs it,
// reporting the stage at which the test exited (the IU charges cycles by exit stage).
#pragma once

#include "geom/kernel.h"
#include "geom/ray.h"

namespace oprt {

// What object memory holds per triangle for this kernel: v0, the edges e1 = v1 - v0,
// e2 = v2 - v0, and the unnormalised normal n = e1 x e2, all prepared once in double from
// the model's vertices and rounded to T (48 bytes in float). Precomputing n makes the
// first, cheapest rejection (ray parallel to the plane, or a degenerate triangle) cost
// one dot product: 4 cycles on one adder and one multiplier (arch/cycle_schedule.h).
template <typename T>
struct MollerTriangle {
  Vec3<T> v0, e1, e2, n;
};

// Prepare a triangle. A zero-area triangle gets n = 0, so det = 0 and it exits at the
// first stage: it can never be hit, whatever the ray.
template <typename T>
MollerTriangle<T> prepare_moller(const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
  const Vec3d e1 = v1 - v0, e2 = v2 - v0;
  const Vec3d n = cross3(e1, e2);
  MollerTriangle<T> t{Vec3<T>(v0), Vec3<T>(e1), Vec3<T>(e2), Vec3<T>(n)};
  if (dot3(n, n) == 0 || (t.n.x == 0 && t.n.y == 0 && t.n.z == 0)) t.n = Vec3<T>(0);
  return t;
}

// Exit stages, in schedule order. A test that reaches the last stage costs the same
// whether it accepts or rejects t, so the cycles charged for a (ray, triangle) pair do not
// depend on which other triangles were tested before it: the work is a property of the
// pair, identical in the reference and in any assignment of spheres to IUs.
enum class TriStage : std::uint8_t {
  det = 0,  // ray parallel to the plane (or degenerate triangle): det == 0
  u = 1,    // first barycentric outside [0, 1]
  v = 2,    // second barycentric outside, or u + v > 1
  t = 3,    // distance computed: accepted, or rejected outside (0, tmax)
};

template <typename T, typename Stage = TriStage>
struct TriangleHit {
  Stage stage = Stage(0);
  bool hit = false;
  T t = kInf<T>, u = 0, v = 0;  // valid when hit
};

// With c = (o - v0) x d the Moller-Trumbore quantities become
//   det = e1.(d x e2) = -d.n,   u det = e2.c,   v det = -e1.c,   t det = (o - v0).n
// (cyclic scalar triple products). Signs are folded so that the comparisons are against
// |det|; the division by det is only done for an accepted hit.
template <typename T>
inline TriangleHit<T> intersect_moller(const Ray<T>& ray, const MollerTriangle<T>& tri) {
  TriangleHit<T> h;
  const T det = -dot3(ray.d, tri.n);
  if (det == 0) return h;
  const Vec3<T> tv = ray.o - tri.v0;
  const Vec3<T> c = cross3(tv, ray.d);
  const T sign = det < 0 ? T(-1) : T(1);
  const T adet = det * sign;
  const T u = dot3(tri.e2, c) * sign;
  h.stage = TriStage::u;
  if (u < 0 || u > adet) return h;
  const T v = -dot3(tri.e1, c) * sign;
  h.stage = TriStage::v;
  if (v < 0 || u + v > adet) return h;
  h.stage = TriStage::t;
  const T t = dot3(tv, tri.n) / det;
  if (!(t > 0 && t < ray.tmax)) return h;
  h.hit = true;
  h.t = t;
  h.u = u / adet;
  h.v = v / adet;
  return h;
}

}  // namespace oprt
