#include "balance/spheres.h"

#include "balance/subdivide.h"
#include "geom/bounding_sphere.h"

#include <numeric>

namespace oprt {

Sphere<double> bound_triangles(const Mesh& mesh, const std::vector<std::uint32_t>& prims) {
  std::vector<Vec3d> pts;
  pts.reserve(prims.size() * 3);
  for (std::uint32_t p : prims)
    for (std::uint32_t k : mesh.triangles[p]) pts.push_back(mesh.vertices[k]);
  return minimal_sphere(pts);
}

std::vector<SphereDef> make_spheres(const Scene& scene, int k, SplitRule rule) {
  std::vector<SphereDef> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Mesh& mesh = scene.objects[o].mesh;
    std::vector<std::vector<std::uint32_t>> clusters;
    if (k <= 1) {
      clusters.emplace_back(mesh.triangles.size());
      std::iota(clusters.back().begin(), clusters.back().end(), 0u);
    } else {
      clusters = subdivide(mesh, k, rule);
    }
    for (auto& prims : clusters) {
      SphereDef d;
      d.object = o;
      d.local = bound_triangles(mesh, prims);
      d.prims = std::move(prims);
      out.push_back(std::move(d));
    }
  }
  return out;
}

}  // namespace oprt
