// The --balance policies that need only the scene's spheres (static over the animation).
#pragma once

#include "balance/assign.h"

#include <string>

namespace oprt {

// Cycle costs the weights are expressed in (defaults: the paper's Table 1).
struct SaNCosts {
  double sphere = 9, transform = 19, triangle = 14.25;  // triangle: mean of the exit-stage costs
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
std::vector<double> sa_n_weights(const Scene& scene, const std::vector<SphereDef>& spheres,
                                 const SaNCosts& costs = {});

}  // namespace oprt
