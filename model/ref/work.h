// Work counts: what the intersection units charge cycles for. Counted by the functional
// traversal (traverse.h), per sphere and ray kind; the cycles they cost under the
// architecture's cycle costs (UnitCycles), the same for the SystemC unit, the analytic level
// and the functional trace (functional_frame.h), which charges each visit.
#pragma once

#include "arch/cycle_costs.h"
#include "geom/ray.h"
#include "geom/triangle.h"

#include <cstdint>

namespace oprt {

struct WorkCounts {
  std::uint64_t sphere_tests = 0;
  std::uint64_t transforms = 0;  // = sphere hits: the ray is carried into the local frame
  std::uint64_t tri_stage[kTriStages] = {};  // triangle tests by exit stage
  std::uint64_t tri_hits = 0;                // accepted at the last stage (subset of tri_stage[t])
  std::uint64_t box_setups = 0;  // --accel bvh: per entered sphere, the ray's reciprocal direction
  std::uint64_t box_tests = 0;   // --accel bvh: nodes fetched and box-tested
  std::uint64_t node_tests = 0;  // --top bvh: nodes of the unit's tree over its spheres tested
                                 // (work of the unit, never of one sphere: 0 in per-sphere tables)

  std::uint64_t tri_tests() const {
    std::uint64_t n = 0;
    for (auto c : tri_stage) n += c;
    return n;
  }
  WorkCounts& operator+=(const WorkCounts& o) {
    sphere_tests += o.sphere_tests;
    transforms += o.transforms;
    for (int i = 0; i < kTriStages; ++i) tri_stage[i] += o.tri_stage[i];
    tri_hits += o.tri_hits;
    box_setups += o.box_setups;
    box_tests += o.box_tests;
    node_tests += o.node_tests;
    return *this;
  }
  bool operator==(const WorkCounts& o) const {
    for (int i = 0; i < kTriStages; ++i)
      if (tri_stage[i] != o.tri_stage[i]) return false;
    return sphere_tests == o.sphere_tests && transforms == o.transforms && tri_hits == o.tri_hits &&
           box_setups == o.box_setups && box_tests == o.box_tests && node_tests == o.node_tests;
  }
};

// Cycles an intersection unit spends, by activity.
struct UnitCycles {
  std::uint64_t sphere = 0, transform = 0, primitive = 0;  // busy
  std::uint64_t box = 0;    // busy, --accel bvh: box set-ups and box tests
  std::uint64_t node = 0;   // busy, --top bvh: node tests of the unit's tree over its spheres
  std::uint64_t stall = 0;  // waiting for object memory or for the bus
  std::uint64_t busy() const { return sphere + transform + box + primitive + node; }
  UnitCycles& operator+=(const UnitCycles& o) {
    sphere += o.sphere;
    transform += o.transform;
    primitive += o.primitive;
    box += o.box;
    node += o.node;
    stall += o.stall;
    return *this;
  }
  bool operator==(const UnitCycles& o) const {
    return sphere == o.sphere && transform == o.transform && primitive == o.primitive && box == o.box &&
           node == o.node && stall == o.stall;
  }
};

inline std::uint64_t primitive_cycles(const WorkCounts& w, const KernelCosts& c) {
  std::uint64_t n = 0;
  for (int k = 0; k < kTriStages; ++k) n += w.tri_stage[k] * c.tri_stage[k];
  return n;
}

inline std::uint64_t box_cycles(const WorkCounts& w, const CycleCosts& c) {
  return w.box_setups * c.box_setup + w.box_tests * c.box;
}

// Cycles of a whole work table (no stalls): what the functional counts predict.
inline UnitCycles work_cycles(const WorkCounts& w, const CycleCosts& c, Kernel kernel) {
  const KernelCosts& k = c.of(kernel);
  UnitCycles u;
  u.sphere = w.sphere_tests * c.sphere;
  u.transform = w.transforms * k.transform;
  u.primitive = primitive_cycles(w, k);
  u.box = box_cycles(w, c);
  u.node = w.node_tests * c.node;
  return u;
}

}  // namespace oprt
