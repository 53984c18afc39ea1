// Per-frame assignment policies. The paper's open problem: even with equal SA x N per unit,
// balance depends on the viewpoint. Consecutive frames of an animation are coherent, so
// `feedback` balances frame f on the per-sphere cost measured in frame f - 1; `view`
// estimates each sphere's load from the frame's camera and lights. Both feed the
// longest-processing-time greedy, then relabel the units so that as little geometry as
// possible moves between object memories.
#pragma once

#include "balance/assign.h"
#include "geom/sphere.h"
#include "scene/scene.h"

#include <cstdint>
#include <vector>

namespace oprt {

// Estimated cycles of each sphere in a frame, from geometry alone:
//   primary rays entering it  ~ pixels x (its solid angle seen from the eye, the cap
//                               2 pi (1 - sqrt(1 - r^2/d^2)), about pi r^2 / d^2, over the
//                               view's solid angle); every pixel if the eye is inside it;
//                               none if it lies outside the view cone;
//   shadow rays entering it   ~ per light: the lit pixels x its solid angle seen from the
//                               light over 4 pi (lights inside the scene shine all round);
//   cost = rays x sphere_cycles + entering rays x (transform_cycles + primitives x
//          triangle_cycles), triangle_cycles the mean cost of a triangle test.
struct ViewCostModel {
  double sphere_cycles = 9, transform_cycles = 19, triangle_cycles = 8;
};
std::vector<double> view_weights(const std::vector<Sphere<double>>& world_spheres,
                                 const std::vector<std::size_t>& primitives, const Camera& camera, int width,
                                 int height, const std::vector<PointLight>& lights, const ViewCostModel& model);

// The same partition with its units renumbered to maximise the geometry each unit keeps
// from `previous` (greedy matching of new sets to old units by shared bytes).
Assignment keep_in_place(const Assignment& next, const Assignment& previous, const std::vector<std::uint64_t>& bytes);

// Bytes that move: geometry a unit holds in `next` that it did not hold in `previous`.
std::uint64_t moved_bytes(const Assignment& next, const Assignment& previous, const std::vector<std::uint64_t>& bytes);

}  // namespace oprt
