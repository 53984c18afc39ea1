// Cycles an intersection unit spends, by activity, and what one sphere visit adds to them.
// Shared by the SystemC unit and the analytic level, so both charge the same work the same
// cycles.
#pragma once

#include "arch/arch.h"
#include "timing/memory_timing.h"
#include "timing/bytes.h"
#include "ref/traverse.h"

#include <cstdint>

namespace oprt::timing {

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

// The cycles of one sphere visit. Memory stalls need the visit's exit stages in memory
// order (SphereVisit::stages), logged only when the memory is not ideal.
template <typename T>
inline UnitCycles visit_cycles(const SphereVisit& v, const Arch& a) {
  UnitCycles c;
  const KernelCosts& k = a.kernel_costs();
  c.sphere = v.work.sphere_tests * a.costs.sphere;
  c.transform = v.work.transforms * k.transform;
  c.primitive = primitive_cycles(v.work, k);
  c.box = box_cycles(v.work, a.costs);
  if (a.memory.model == MemoryModel::latency && v.work.transforms && v.stages) {
    StreamCosts s;
    s.latency = static_cast<std::uint32_t>(a.memory.latency_cycles);
    s.bytes_per_cycle = static_cast<std::uint32_t>(a.memory.bytes_per_cycle);
    s.triangle_bytes = Bytes<T>::triangle(a.kernel);
    s.node_bytes = Bytes<T>::node;
    s.lead = k.transform + (v.work.box_setups ? a.costs.box_setup : 0);
    s.triangle = k.tri_stage;
    s.box = a.costs.box;
    c.stall = stream_stall(s, v.stages, static_cast<std::uint32_t>(v.work.tri_tests() + v.work.box_tests));
  }
  return c;
}

// What a unit records of one sphere visit: its cycles, its work (per kind and sphere) and
// the bytes it streams from object memory. Shared by the SystemC unit and the analytic level.
template <typename T>
inline UnitCycles charge_visit(const SphereVisit& v, const Arch& a, std::vector<WorkCounts>& per_sphere,
                               std::uint64_t& memory_bytes) {
  per_sphere[v.sphere] += v.work;
  memory_bytes += v.work.tri_tests() * Bytes<T>::triangle(a.kernel) + v.work.box_tests * Bytes<T>::node;
  return visit_cycles<T>(v, a);
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

}  // namespace oprt::timing
