// A frame's functional work, computed before it is timed. Which spheres a ray enters, the
// work of each visit and each unit's answer do not depend on time (ref/frame_trace.h), so the
// whole frame is traced first, on every thread the pool allows; then the timed model (the
// SystemC modules, or the analytic recurrence) places that work in time. The transactions
// still carry the rays and the units' answers; the GPP merges the answers and checks them
// against this record. Plain C++, no SystemC.
//
// Storage is sparse: a unit whose ray enters none of its spheres, the common case, has no
// record (it tested every sphere in its registers, or with a tree over its spheres only the
// root, and answered "miss" / "not occluded").
#pragma once

#include "hw/arch.h"
#include "hw/payloads.h"
#include "hw/unit_cycles.h"
#include "ref/frame_trace.h"

#include <array>
#include <cstdint>
#include <vector>

namespace oprt::hw {

// One unit's work on one ray, when it entered at least one sphere.
struct UnitRayWork {
  std::uint32_t ray = 0;
  std::uint32_t sphere_tests = 0;  // register entries tested (a shadow ray stops at its first occluder)
  std::uint32_t node_tests = 0;    // --top bvh: nodes of the unit's tree tested
  std::uint32_t transform = 0, box = 0, primitive = 0, stall = 0;  // cycles; stall: memory streaming
  std::uint32_t first_visit = 0, visits = 0;  // its entered spheres (UnitTrace::visits), in register order
  std::uint32_t hit = kNone;                  // primary: index into UnitTrace::hits, if it found one
  bool occluded = false;                      // shadow: it found an occluder
};

// A sphere a unit entered on a ray.
struct VisitWork {
  std::uint32_t entry = 0;   // position in the unit's registers
  std::uint32_t sphere = 0;  // global sphere id
  std::uint32_t spheres_before = 0, nodes_before = 0;  // tests since the previous entered sphere, this one's included
  std::uint32_t box = 0, primitive = 0, stall = 0;  // cycles (the transform is the kernel's cost)
  std::uint32_t tri_tests = 0, box_tests = 0;       // what it streamed from object memory
};

// One unit's records for a frame, in ray order. A unit reads only its own: they lie
// together in memory, and finding the record of ray r takes a bit and a popcount in a
// small index (one bit per ray, one count per 64 rays) instead of a search.
template <typename T>
struct UnitTrace {
  std::vector<UnitRayWork> work;
  std::vector<VisitWork> visits;
  std::vector<HitRecord<T>> hits;
  std::vector<std::uint64_t> has;   // bit r % 64 of word r / 64: ray r has a record
  std::vector<std::uint32_t> rank;  // per word: records of the rays before it

  const UnitRayWork* find(std::uint32_t r) const {
    const std::uint64_t m = has[r >> 6];
    const std::uint32_t bit = r & 63;
    if (!((m >> bit) & 1)) return nullptr;
    return &work[rank[r >> 6] + static_cast<std::uint32_t>(__builtin_popcountll(m & ((std::uint64_t{1} << bit) - 1)))];
  }
};

template <typename T>
struct FunctionalFrame {
  // Rays in functional order: per pixel its primary ray, then its shadow rays in light order.
  // A ray's id everywhere in the timed model is its index here.
  std::vector<RayRecord<T>> rays;
  std::vector<std::uint32_t> pixel_rays;  // pixel p owns rays [pixel_rays[p], pixel_rays[p + 1])
  std::vector<UnitTrace<T>> units;
  FrameImage image;                       // what the frame renders (the GPP's pixels must agree)
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;  // [kind][sphere]
  std::vector<UnitCycles> unit_cycles;    // per unit, busy and memory stall (no bus time)
  std::vector<std::uint32_t> unit_entries;  // per unit: spheres in its registers this frame
  std::vector<char> unit_top;             // per unit: it walks a tree over its spheres (--top bvh)
  std::vector<std::array<std::uint64_t, kRayKinds>> unit_node_tests;  // per unit and ray kind
  std::uint32_t sphere_cost = 0;          // cycles per sphere test
  std::uint32_t node_cost = 0;            // cycles per node test (--top bvh)

  std::uint32_t ray_count() const { return static_cast<std::uint32_t>(rays.size()); }
  // Unit u's record for ray r, or null if the ray entered none of its spheres.
  const UnitRayWork* find(std::uint32_t r, std::uint32_t u) const { return units[u].find(r); }
  // Cycles unit u spends on a ray (busy and memory stall), with its record or without.
  UnitCycles breakdown(const UnitRayWork* w, std::uint32_t u) const {
    UnitCycles c;
    if (!w) {
      if (unit_top[u]) c.node = node_cost;  // the root, missed
      else c.sphere = std::uint64_t{unit_entries[u]} * sphere_cost;
      return c;
    }
    c.sphere = std::uint64_t{w->sphere_tests} * sphere_cost;
    c.node = std::uint64_t{w->node_tests} * node_cost;
    c.transform = w->transform;
    c.box = w->box;
    c.primitive = w->primitive;
    c.stall = w->stall;
    return c;
  }
  // Unit u's answer to ray r.
  UnitAnswer<T> answer(const UnitRayWork* w, std::uint32_t u) const {
    UnitAnswer<T> a;
    if (w) {
      a.occluded = w->occluded;
      if (w->hit != kNone) a.hit = units[u].hits[w->hit];
    }
    return a;
  }
};

// Trace every pixel of the frame for the units' registers (units[u] is unit u's). Reuses
// `out`'s storage from frame to frame.
template <typename T>
void trace_functional(FunctionalFrame<T>& out, const SceneGeometry<T>& geometry,
                      const std::vector<IuRegisters<T>>& units, const CameraRays& camera, const Shader<T>& shader,
                      const Arch& arch, int width, int height);

// Calls phase(state, cycles) for each phase of unit u's work on ray r in time order, as the
// unit performs it: sphere tests (and node tests of its tree), and for each entered sphere
// its transform, box tests, triangle tests and memory stall. Consecutive tests before a
// sphere is entered form one phase of node tests, then one of sphere tests. State codes are
// UnitState's (intersection_unit.h): sphere 1, transform 2, primitive 3, stall 4, box 5,
// node 6.
template <typename T, typename Phase>
void for_each_phase(const FunctionalFrame<T>& f, const UnitRayWork* w, std::uint32_t u, std::uint32_t transform_cost,
                    Phase&& phase) {
  auto emit = [&](std::uint8_t state, std::uint64_t cycles) {
    if (cycles) phase(state, cycles);
  };
  if (!w) {
    if (f.unit_top[u]) emit(6, f.node_cost);
    else emit(1, std::uint64_t{f.unit_entries[u]} * f.sphere_cost);
    return;
  }
  std::uint32_t spheres = 0, nodes = 0;
  for (std::uint32_t i = w->first_visit; i < w->first_visit + w->visits; ++i) {
    const VisitWork& v = f.units[u].visits[i];
    emit(6, std::uint64_t{v.nodes_before} * f.node_cost);
    emit(1, std::uint64_t{v.spheres_before} * f.sphere_cost);
    spheres += v.spheres_before;
    nodes += v.nodes_before;
    emit(2, transform_cost);
    emit(5, v.box);
    emit(3, v.primitive);
    emit(4, v.stall);
  }
  emit(6, std::uint64_t{w->node_tests - nodes} * f.node_cost);
  emit(1, std::uint64_t{w->sphere_tests - spheres} * f.sphere_cost);
}

extern template struct FunctionalFrame<float>;
extern template struct FunctionalFrame<double>;
extern template void trace_functional(FunctionalFrame<float>&, const SceneGeometry<float>&,
                                      const std::vector<IuRegisters<float>>&, const CameraRays&, const Shader<float>&,
                                      const Arch&, int, int);
extern template void trace_functional(FunctionalFrame<double>&, const SceneGeometry<double>&,
                                      const std::vector<IuRegisters<double>>&, const CameraRays&,
                                      const Shader<double>&, const Arch&, int, int);

}  // namespace oprt::hw
