// The --balance policies that need only the scene's spheres (static over the animation), and
// where the per-frame ones start.
#pragma once

#include "balance/assign.h"
#include "balance/spatial.h"

#include <optional>
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

// "paper", "round_robin", "sa_n" or "spatial" (balance/spatial.h: the spheres where they are
// at frame 0, their sa_n weights as costs, at `locality`); units = min(requested, spheres).
Assignment static_assignment(const std::string& policy, const Scene& scene, const std::vector<SphereDef>& spheres,
                             std::size_t units, const SaNCosts& costs = {}, double locality = kDefaultLocality);

// The assignment a run starts from: a static policy's own (spatial at `locality`, or at its
// default without one); "feedback" and "view" start from sa_n (nothing is measured before
// the first frame), feedback with a locality from spatial at it.
Assignment initial_assignment(const std::string& policy, std::optional<double> locality, const Scene& scene,
                              const std::vector<SphereDef>& spheres, std::size_t units, const SaNCosts& costs = {});

// The paper's SA x N made into expected cycles per primary ray, with no knowledge of the
// viewpoint. Per primary ray a unit tests each of its spheres against the primary ray and
// one shadow ray per light: (1 + L) sphere tests, whatever the sphere's size. Sphere s is
// entered by
//  - primary rays: the viewpoint is unknown, so they are taken as isotropic random lines
//    through the scene. For such lines, the fraction that meet a convex body s lying in
//    the convex body H they cross is A_s / A_H (Crofton; at most 1 when s sticks out of H).
//    H is the convex hull of the scene's geometry at frame 0 (hull_area.h): every ray that matters
//    starts in it (at a camera looking at the scene, or on a surface for shadow rays).
//    The hull, not a bounding sphere: a room's wall spheres reach far outside the room
//    and the sphere around them has 3.6x the hull's area (docs/results.md).
//  - shadow rays: these are not isotropic lines, every one ends at a light. Seen from
//    light l they arrive from all around, so the fraction passing through s is the solid
//    angle s subtends at l over 4 pi, (1 - sqrt(1 - r^2 / d^2)) / 2, or 1 with the light
//    inside s. The lights are part of the scene, not of the viewpoint.
// Each entry costs a transform and N_s triangle tests at their mean cost:
//   w_s = (1 + L) sphere + (min(1, A_s / A_H) + sum_l cap_l(s)) (transform + N_s triangle)
// Spheres at their frame-0 positions.
// With a BVH an entry no longer tests N_s triangles: by the same argument a ray that enters
// the sphere enters a node's box with probability A_box / A_s, so an entry costs
//   transform + box_setup + box                      (the root)
//   + sum over interior nodes (A_n / A_s) 2 box      (its children's boxes)
//   + sum over leaves (A_l / A_s) N_l triangle
// -- the SAH cost of the sphere's tree. Both forms ignore that a nearest-hit walk stops
// early (and a shadow ray at its first occluder), so they overestimate alike.
std::vector<double> sa_n_weights(const Scene& scene, const std::vector<SphereDef>& spheres,
                                 const SaNCosts& costs = {});

}  // namespace oprt
