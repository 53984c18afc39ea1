// What the feedback policy reads of a timed frame (balance/policy_driver.h MeasuredFrame),
// from the frame's run at either level.
#pragma once

#include "arch/arch.h"
#include "balance/policy_driver.h"
#include "ref/functional_frame.h"
#include "ref/work.h"
#include "timing/unit_run.h"

namespace oprt::timing {

inline MeasuredFrame measured_frame(const FrameRun& run, const Arch& arch) {
  MeasuredFrame m;
  const std::size_t spheres = run.per_sphere[0].size();
  m.sphere_cycles.assign(spheres, 0);
  m.sphere_tests.assign(spheres, 0);
  for (int k = 0; k < kRayKinds; ++k)
    for (std::size_t s = 0; s < spheres; ++s) {
      m.sphere_cycles[s] += static_cast<double>(work_cycles(run.per_sphere[k][s], arch.costs, arch.kernel).busy());
      m.sphere_tests[s] += static_cast<double>(run.per_sphere[k][s].sphere_tests);
    }
  m.slices = kWorkSlices;
  m.sphere_slices = run.sphere_slices;
  m.unit_node_slices = run.unit_node_slices;
  for (const UnitRun& u : run.units) m.unit_node_cycles.push_back(u.cycles.node);
  m.route_cycles = run.route.cycles;
  m.rays = run.total_rays();
  return m;
}

}  // namespace oprt::timing
