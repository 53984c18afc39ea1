// Work counts: what the intersection units charge cycles for. Counted by the functional
// traversal (traverse.h), per sphere and ray kind; the timed model and the analytic level
// multiply them by the architecture's cycle costs.
#pragma once

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

}  // namespace oprt
