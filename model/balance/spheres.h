// Bounding spheres of the scene, built once before the animation in each object's local
// frame: one per object, or K per object with --subdivide K (subdivide.cpp).
#pragma once

#include "balance/subdivide.h"
#include "geom/sphere.h"
#include "scene/scene.h"

#include <cstdint>
#include <vector>

namespace oprt {

struct SphereDef {
  std::uint32_t object = 0;
  std::vector<std::uint32_t> prims;  // triangle indices into the object's mesh
  Sphere<double> local;              // minimal enclosing sphere of those triangles
  double surface_area() const { return 4 * 3.14159265358979323846 * local.r * local.r; }
  // The paper's load estimate (section 5.1): surface area x primitive count, in local units
  // (a rigid motion does not change it).
  double sa_n() const { return surface_area() * static_cast<double>(prims.size()); }
};

// Spheres in scene order: object 0's spheres first. K = 1 is the paper's evaluation.
std::vector<SphereDef> make_spheres(const Scene& scene, int subdivide_k, SplitRule rule = SplitRule::balanced_san);

// Minimal enclosing sphere of a set of an object's triangles.
Sphere<double> bound_triangles(const Mesh& mesh, const std::vector<std::uint32_t>& prims);

}  // namespace oprt
