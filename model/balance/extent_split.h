// Split by extent: an object's triangles grouped into bounding spheres by where they are,
// so that no sphere is larger than it needs to be (a material group of a room's furniture
// spread over the whole room becomes one sphere per piece, not one sphere around the room).
// The rule, its stopping criterion and the reasoning are beside the code in extent_split.cpp.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <vector>

namespace oprt {

// What the stopping rule weighs, in cycles (defaults: the paper's Table 1, a triangle test
// at the mean of its exit-stage costs) and in the object's local units.
struct ExtentCosts {
  double sphere = 9, transform = 19, triangle = 14.25;
  // Area of the region rays cross (the scene's convex hull at frame 0, policy.h) divided by
  // the square of the object's stretch at frame 0: the hull's area in local units.
  double hull_area = 1;
};

// The prims (triangle indices into `mesh`) split into clusters, each listed ascending, in
// tree order (a cut's lower side first). Deterministic; every prim in exactly one cluster.
std::vector<std::vector<std::uint32_t>> split_by_extent(const Mesh& mesh, const std::vector<std::uint32_t>& prims,
                                                        const ExtentCosts& costs);

}  // namespace oprt
