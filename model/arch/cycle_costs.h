// Cycles charged per IU operation. Defaults: the paper's Table 1 (sphere 9, transform 19,
// triangle 4 to 22), with the triangle test's per-stage costs taken from its schedule
// (cycle_schedule.cpp: 4, 14, 17, 22) and the transform's 19 confirmed by its schedule.
// --accel bvh adds the box set-up (the local ray's reciprocal direction, once per entered
// sphere: 12) and the box test (per node: 13), both from their schedules. --top bvh adds the
// test of a node of the unit's tree over its spheres (13, its schedule).
// The sphere test keeps Table 1's 9 so that the paper's figures reproduce; its schedules
// say 10 for the textbook form and 14 for the stable form the model runs (set
// "costs": {"sphere": 14} in an architecture file to charge that). The watertight kernel
// has its own transform (it also picks the ray's dominant axis: 20) and its own exit
// stages (uv 18, w 20, det 21, t 27), both from its schedules. Every value can be
// overridden by the architecture file.
#pragma once

#include "geom/kernel.h"

#include <cstdint>

namespace oprt {

// What a kernel's work costs: the ray's transform into the local frame (each kernel needs
// its own per-ray set-up there) and a triangle test by exit stage.
struct KernelCosts {
  std::uint32_t transform = 0;
  std::uint32_t tri_stage[kTriStages] = {};
};

struct CycleCosts {
  std::uint32_t sphere = 9;
  KernelCosts moller{19, {4, 14, 17, 22}};
  KernelCosts watertight{20, {18, 20, 21, 27}};
  std::uint32_t box_setup = 12;  // --accel bvh, per entered sphere
  std::uint32_t box = 13;        // --accel bvh, per node
  std::uint32_t node = 13;       // --top bvh, per node of a unit's tree over its spheres

  const KernelCosts& of(Kernel k) const { return k == Kernel::watertight ? watertight : moller; }
  KernelCosts& of(Kernel k) { return k == Kernel::watertight ? watertight : moller; }
};

// The schedules' own numbers (what the default table above is checked against).
CycleCosts scheduled_costs();

}  // namespace oprt
