// Bounding spheres of the scene, built once before the animation in each object's local
// frame: one per object or per piece of an object (split by extent), each into K with
// --subdivide K (subdivide.cpp).
#pragma once

#include "balance/subdivide.h"
#include "geom/sphere.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

struct SphereDef {
  std::uint32_t object = 0;
  std::vector<std::uint32_t> prims;  // triangle indices into the object's mesh
  Sphere<double> local;              // minimal enclosing sphere of those triangles
  // The object's stretch at frame 0 (max_stretch of its matrix, rounded up by 1e-9: 1 for
  // a rigid motion): local lengths times this are world lengths.
  double scale = 1;
  double world_radius() const { return local.r * scale; }
  // In world units: the rays a sphere meets depend on its size in the scene, not in the
  // units its mesh was written in (a toy car's wheel modelled at 0.0005 and scaled up).
  double surface_area() const { return 4 * 3.14159265358979323846 * world_radius() * world_radius(); }
  // The paper's load estimate (section 5.1): surface area x primitive count.
  double sa_n() const { return surface_area() * static_cast<double>(prims.size()); }
};

// How objects become spheres before --subdivide.
enum class ObjectSplit {
  count,   // one sphere per object, objects as loaded (a BART group is split by count
           // into objects of at most --max-object-triangles by its loader)
  extent,  // each rigid object split by where its triangles are (balance/extent_split.h)
};

// "count" | "extent"; "" is the format's default: extent for BART .aff and glTF (their
// objects are material groups or nodes, which may span a scene), count for oprt JSON (the
// paper's scenes: an object as written is one sphere).
ObjectSplit object_split_named(const std::string& name, const std::string& scene_path);
const char* to_string(ObjectSplit s);

// Spheres in scene order: object 0's spheres first. K = 1 is the paper's evaluation; with
// K > 1 each sphere the split gives is subdivided into K (subdivide.h).
std::vector<SphereDef> make_spheres(const Scene& scene, int subdivide_k, SplitRule rule = SplitRule::balanced_san,
                                    ObjectSplit split = ObjectSplit::count);

// Minimal enclosing sphere of a set of an object's triangles.
Sphere<double> bound_triangles(const Mesh& mesh, const std::vector<std::uint32_t>& prims);

}  // namespace oprt
