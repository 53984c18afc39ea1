// What a partition of the spheres over the units buys when a ray goes only to the units
// whose bound it enters (multicast routing, issue 21), in plain C++ for the router, the
// tests and `oprt info`: each unit's world bound at a frame, the expected fan-out of a ray,
// and the load imbalance of the units' estimated costs.
#pragma once

#include "balance/assign.h"
#include "balance/spheres.h"
#include "geom/bvh.h"

#include <vector>

namespace oprt {

// Per sphere, the world box of its triangles at `frame`: its object's matrix at that frame
// applied to each vertex (a deforming object's vertices as they are at that frame). A
// sphere hidden at that frame gets its box too: a placement needs to know where it is.
// Exact in double up to rounding; the router's conservative bounds (ref/top_tree.h,
// world_bounds: the local box carried into world space, widened by the frame's rounding
// margin) contain it.
std::vector<Box<double>> sphere_world_boxes(const Scene& scene, const std::vector<SphereDef>& spheres, int frame);

// Per unit, the union of its spheres' boxes (empty if all of them are empty: a unit whose
// spheres are all hidden needs no ray).
std::vector<Box<double>> unit_bounds(const Assignment& a, const std::vector<Box<double>>& sphere_box);

Box<double> union_of(const std::vector<Box<double>>& boxes);

// The expected number of units a ray entering `scene` enters, sum over units of
// A(unit bound) / A(scene): of the isotropic random lines that meet a convex body H, the
// fraction that meet a convex body K inside it is A_K / A_H (Crofton, the argument behind
// the sa_n estimate, policy.h), and an expectation adds up over units. The ratio is the
// SAH's. A scene bound with no area (every box a point or on one line) counts each unit
// with a bound as entered.
double expected_fanout(const std::vector<Box<double>>& unit_bound, const Box<double>& scene);

// The largest unit load over the mean (units with no sphere count in the mean); 1 when
// every load is 0.
double load_imbalance(const std::vector<double>& unit_load);

struct PartitionQuality {
  std::vector<Box<double>> unit_bound;  // per unit
  Box<double> scene_bound;              // the union of every sphere's box
  std::vector<double> unit_load;        // per unit, the sum of its spheres' weights
  double fanout = 0;                    // expected_fanout(unit_bound, scene_bound)
  double imbalance = 1;                 // load_imbalance(unit_load)
};
PartitionQuality partition_quality(const Assignment& a, const std::vector<Box<double>>& sphere_box,
                                   const std::vector<double>& weight);

}  // namespace oprt
