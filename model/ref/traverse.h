// The work of one intersection unit on one ray, as a pure function: test the ray against
// each of the unit's spheres in order; on a hit carry the ray into the sphere's local frame
// and test the sphere's triangles. The reference renderer calls it with every sphere (one
// unit holding the whole scene); the timed model's IUs and the analytic level call it with
// the spheres assigned to each unit. Images agree by construction: the nearest hit is
// chosen by (t, object, primitive), a total order that does not depend on which unit found
// it or in which order.
#pragma once

#include "ref/frame_setup.h"
#include "ref/work.h"

#include <limits>

namespace oprt {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

template <typename T>
struct HitRecord {
  T t = kInf<T>;
  std::uint32_t object = kNone, prim = kNone, sphere = kNone;
  T u = 0, v = 0;
  bool valid() const { return object != kNone; }
};

template <typename T>
inline bool closer(const HitRecord<T>& a, const HitRecord<T>& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.object != b.object) return a.object < b.object;
  return a.prim < b.prim;
}

// Nearest hit over spheres[0..n). `work` is indexed by sphere id.
// Every triangle of an entered sphere is tested against the ray's own tmax, never against
// the nearest hit so far: the exit stage of a (ray, triangle) pair, and so its cost, is
// then the same in every unit and in every order (see geom/triangle.h).
template <typename T>
HitRecord<T> trace_nearest(const SceneGeometry<T>& g, const FrameSetup<T>& f,
                           const std::uint32_t* spheres, std::size_t n, const Ray<T>& ray,
                           WorkCounts* work) {
  HitRecord<T> best;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t s = spheres[i];
    WorkCounts& w = work[s];
    ++w.sphere_tests;
    if (!hit_sphere(ray, f.world_sphere[s])) continue;
    ++w.transforms;
    const std::uint32_t obj = g.object[s];
    const Ray<T> local = f.to_local[obj].ray(ray);
    const BlockHit<T> h = nearest_in_block(g.tris, g.first[s], g.first[s + 1], local, w.tri_stage, &w.tri_hits);
    if (!h.valid()) continue;
    const HitRecord<T> c{h.t, obj, g.prim[h.index], s, h.u, h.v};
    if (closer(c, best)) best = c;
  }
  return best;
}

// Any hit in (0, tmax) over spheres[0..n): the unit stops at its first occluder.
template <typename T>
bool trace_any(const SceneGeometry<T>& g, const FrameSetup<T>& f, const std::uint32_t* spheres,
               std::size_t n, const Ray<T>& ray, WorkCounts* work) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t s = spheres[i];
    WorkCounts& w = work[s];
    ++w.sphere_tests;
    if (!hit_sphere(ray, f.world_sphere[s])) continue;
    ++w.transforms;
    const Ray<T> local = f.to_local[g.object[s]].ray(ray);
    if (any_in_block(g.tris, g.first[s], g.first[s + 1], local, w.tri_stage, &w.tri_hits)) return true;
  }
  return false;
}

}  // namespace oprt
