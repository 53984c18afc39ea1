// Cycles an intersection unit spends, by activity, and what one sphere visit adds to them.
// Shared by the SystemC unit and the analytic level, so both charge the same work the same
// cycles.
#pragma once

#include "hw/arch.h"
#include "hw/memory_timing.h"
#include "hw/payloads.h"
#include "ref/traverse.h"

#include <cstdint>

namespace oprt::hw {

struct UnitCycles {
  std::uint64_t sphere = 0, transform = 0, primitive = 0;  // busy
  std::uint64_t stall = 0;  // waiting for object memory or for the bus
  std::uint64_t busy() const { return sphere + transform + primitive; }
  UnitCycles& operator+=(const UnitCycles& o) {
    sphere += o.sphere;
    transform += o.transform;
    primitive += o.primitive;
    stall += o.stall;
    return *this;
  }
  bool operator==(const UnitCycles& o) const {
    return sphere == o.sphere && transform == o.transform && primitive == o.primitive && stall == o.stall;
  }
};

inline std::uint64_t primitive_cycles(const WorkCounts& w, const KernelCosts& c) {
  std::uint64_t n = 0;
  for (int k = 0; k < kTriStages; ++k) n += w.tri_stage[k] * c.tri_stage[k];
  return n;
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
  if (a.memory.model == MemoryModel::latency && v.work.transforms && v.stages) {
    const auto n = static_cast<std::uint32_t>(v.work.tri_tests());
    c.stall = stream_stall(a.memory.latency_cycles, a.memory.bytes_per_cycle, Bytes<T>::triangle(a.kernel), k.transform,
                           v.stages, n, k.tri_stage);
  }
  return c;
}

// What a unit records of one sphere visit: its cycles, its work (per kind and sphere) and
// the bytes it streams from object memory. Shared by the SystemC unit and the analytic level.
template <typename T>
inline UnitCycles charge_visit(const SphereVisit& v, const Arch& a, std::vector<WorkCounts>& per_sphere,
                               std::uint64_t& memory_bytes) {
  per_sphere[v.sphere] += v.work;
  if (v.work.transforms) memory_bytes += v.work.tri_tests() * Bytes<T>::triangle(a.kernel);
  return visit_cycles<T>(v, a);
}

// Cycles of a whole work table (no stalls): what the functional counts predict.
inline UnitCycles work_cycles(const WorkCounts& w, const CycleCosts& c, Kernel kernel) {
  const KernelCosts& k = c.of(kernel);
  UnitCycles u;
  u.sphere = w.sphere_tests * c.sphere;
  u.transform = w.transforms * k.transform;
  u.primitive = primitive_cycles(w, k);
  return u;
}

}  // namespace oprt::hw
