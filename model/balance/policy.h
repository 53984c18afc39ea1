// The --balance policies that need only the scene's spheres (static over the animation).
#pragma once

#include "balance/assign.h"

#include <string>

namespace oprt {

// A node of a sphere's BVH as the weights see it: its box's surface area (local units) and,
// for a leaf, its triangle count (0: interior node, whose two children are box-tested when
// a ray enters it).
struct NodeArea {
  double area = 0;
  std::uint32_t triangles = 0;
};

// Cycle costs the weights are expressed in (defaults: the paper's Table 1).
struct SaNCosts {
  double sphere = 9, transform = 19, triangle = 14.25;  // triangle: mean of the exit-stage costs
  double box_setup = 12, box = 13;
  // --accel bvh: per sphere its nodes (empty: brute force, every triangle per entry).
  std::vector<std::vector<NodeArea>> bvh;
};

// "paper", "round_robin" or "sa_n"; units = min(requested, spheres).
Assignment static_assignment(const std::string& policy, const Scene& scene, const std::vector<SphereDef>& spheres,
                             std::size_t units, const SaNCosts& costs = {});

// The paper's SA x N made into cycles per ray. For uniformly random lines, the fraction
// that enter a convex body inside another is the ratio of their surface areas (Crofton),
// so a sphere of area A_s in a scene bounded by area A costs, per ray,
//   sphere + (A_s / A) (transform + N_s triangle)
// -- SA x N plus the two terms SA x N leaves out: every sphere is tested by every ray
// whatever its size, and each entry costs a transform. A is the area of the sphere
// bounding the whole scene (at frame 0), the convex body all rays of interest cross.
// With a BVH the entry term is no longer N_s triangles: by the same argument a node's box is
// entered with probability A_box / A, so a sphere costs, per ray,
//   sphere + (A_s / A)(transform + box_setup + box)          (the root, on entry)
//          + sum over interior nodes (A_n / A) 2 box          (its children's boxes)
//          + sum over leaves (A_l / A) N_l triangle
// -- the SAH cost of the sphere's tree. Both ignore that a nearest-hit walk stops early
// (and a shadow ray at its first occluder), so they overestimate alike.
std::vector<double> sa_n_weights(const Scene& scene, const std::vector<SphereDef>& spheres,
                                 const SaNCosts& costs = {});

}  // namespace oprt
