// The work of one intersection unit on one ray, as a pure function of what the unit holds:
// its configuration registers (the spheres assigned to it, with their world spheres and
// world -> local matrices, written by the GPP each frame) and its object memory (the
// spheres' triangles). Test the ray against each sphere in register order; on a hit carry
// the ray into the sphere's local frame and test the sphere's triangles.
//
// The reference renderer calls it with one register file holding every sphere; the timed
// model's IUs and the analytic level with each unit's own. Images agree by construction:
// the nearest hit is chosen by (t, object, primitive), a total order that does not depend
// on which unit found it or in which order. Each sphere visit is reported to a visitor with
// its work, so every caller charges the same counts.
#pragma once

#include "ref/sphere_visit.h"
#include "ref/top_traverse.h"

namespace oprt {

// Nearest hit over the unit's spheres. Every triangle of an entered sphere is tested
// against the ray's own tmax, never against the nearest hit so far: the exit stage of a
// (ray, triangle) pair, and so its cost, is then the same in every unit and in every order
// (see geom/triangle.h). visit(const SphereVisit&) is called once per sphere tested.
// `key`: the ray's share key (share_key); a flat unit tests every entry of its registers
// as it streams them, and does not enter a copy whose share the ray is not (its sphere
// test is made, and charged, as the entry passes).
template <typename T, typename Visit>
HitRecord<T> trace_nearest(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, const Ray<T>& ray,
                           Visit&& visit, StageLog* log = nullptr, std::uint32_t key = 0) {
  if (!regs.top.empty()) return trace_nearest_top(mem, regs, ray, visit, log, key);  // ref/top_traverse.h
  HitRecord<T> best;
  for_each_sphere_test(regs, ray, [&](std::uint32_t i, bool sphere_hit) {
    SphereVisit v{i, regs.sphere[i], {}};
    v.work.sphere_tests = 1;
    if (sphere_hit && regs.mine(i, key)) keep_closer(mem, v.sphere, nearest_in_sphere(mem, regs, i, ray, v, log), best);
    visit(v);
    return false;
  });
  return best;
}

// Any hit in (0, tmax) over the unit's spheres: the unit stops at its first occluder.
template <typename T, typename Visit>
bool trace_any(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, const Ray<T>& ray, Visit&& visit,
               StageLog* log = nullptr, std::uint32_t key = 0) {
  if (!regs.top.empty()) return trace_any_top(mem, regs, ray, visit, log, key);  // ref/top_traverse.h
  bool occluded = false;
  for_each_sphere_test(regs, ray, [&](std::uint32_t i, bool sphere_hit) {
    SphereVisit v{i, regs.sphere[i], {}};
    v.work.sphere_tests = 1;
    if (sphere_hit && regs.mine(i, key)) occluded = any_in_sphere(mem, regs, i, ray, v, log);
    visit(v);
    return occluded;
  });
  return occluded;
}

// A visitor that adds each visit's work to a per-sphere table.
struct AccumulateWork {
  WorkCounts* per_sphere;
  void operator()(const SphereVisit& v) const {
    if (v.sphere != kNone) per_sphere[v.sphere] += v.work;
  }
};

}  // namespace oprt
