#include "balance/spheres.h"

#include "balance/extent_split.h"
#include "balance/hull_area.h"
#include "balance/subdivide.h"
#include "geom/bounding_sphere.h"
#include "base/error.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <numeric>

namespace oprt {

Sphere<double> bound_triangles(const Mesh& mesh, const std::vector<std::uint32_t>& prims) {
  std::vector<Vec3d> pts;
  pts.reserve(prims.size() * 3);
  for (std::uint32_t p : prims)
    for (std::uint32_t k : mesh.triangles[p]) pts.push_back(mesh.vertices[k]);
  return minimal_sphere(pts);
}

ObjectSplit object_split_named(const std::string& name, const std::string& scene_path) {
  if (name == "count") return ObjectSplit::count;
  if (name == "extent") return ObjectSplit::extent;
  if (!name.empty()) throw InputError("--split", name, "unknown split (expected count or extent)");
  std::string ext = std::filesystem::path(scene_path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".aff" || ext == ".gltf" || ext == ".glb" ? ObjectSplit::extent : ObjectSplit::count;
}

const char* to_string(ObjectSplit s) { return s == ObjectSplit::extent ? "extent" : "count"; }

std::vector<SphereDef> make_spheres(const Scene& scene, int k, SplitRule rule, ObjectSplit split) {
  ExtentCosts costs;  // the paper's Table 1
  const double hull = split == ObjectSplit::extent ? scene_hull_area(scene) : 0;
  std::vector<SphereDef> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    const Mesh& mesh = object.mesh;
    const double scale = max_stretch(object.motion->at(0));
    std::vector<std::uint32_t> all(mesh.triangles.size());
    std::iota(all.begin(), all.end(), 0u);
    std::vector<std::vector<std::uint32_t>> pieces;
    // A deforming object's triangles move apart: a split of its frame-0 shape would not
    // stay compact, so it stays whole (its sphere is re-bounded every frame).
    if (split == ObjectSplit::extent && !object.deform) {
      costs.hull_area = hull / (scale * scale);
      pieces = split_by_extent(mesh, all, costs);
    } else {
      pieces.push_back(std::move(all));
    }
    for (auto& piece : pieces) {
      std::vector<std::vector<std::uint32_t>> clusters;
      if (k <= 1) clusters.push_back(std::move(piece));
      else clusters = subdivide(mesh, piece, k, rule);
      for (auto& prims : clusters) {
        SphereDef d;
        d.object = o;
        d.local = bound_triangles(mesh, prims);
        d.scale = scale;
        d.prims = std::move(prims);
        out.push_back(std::move(d));
      }
    }
  }
  return out;
}

}  // namespace oprt
