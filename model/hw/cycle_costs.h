// Cycles charged per IU operation. Defaults: the paper's Table 1 (sphere 9, transform 19,
// triangle 4 to 22), with the triangle test's per-stage costs taken from its schedule
// (cycle_schedule.cpp: 4, 14, 17, 22) and the transform's 19 confirmed by its schedule.
// --accel bvh adds the box set-up (the local ray's reciprocal direction, once per entered
// sphere: 12) and the box test (per node: 13), both from their schedules.
// The sphere test keeps Table 1's 9 so that the paper's figures reproduce; its schedules
// say 10 for the textbook form and 14 for the stable form the model runs (set
// "costs": {"sphere": 14} in an architecture file to charge that). Every value can be
// overridden by the architecture file.
#pragma once

#include "geom/triangle.h"

#include <cstdint>

namespace oprt {

struct CycleCosts {
  std::uint32_t sphere = 9;
  std::uint32_t transform = 19;
  std::uint32_t tri_stage[kTriStages] = {4, 14, 17, 22};
  std::uint32_t box_setup = 12;
  std::uint32_t box = 13;
};

// The schedules' own numbers (what the default table above is checked against).
CycleCosts scheduled_costs();

}  // namespace oprt
