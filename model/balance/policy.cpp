#include "balance/policy.h"

#include "geom/bounding_sphere.h"

#include <stdexcept>

namespace oprt {

std::vector<double> sa_n_weights(const Scene& scene, const std::vector<SphereDef>& spheres, const SaNCosts& c) {
  // The scene's bound at frame 0: the minimal sphere around every sphere's axis extremes.
  std::vector<Vec3d> extremes;
  for (const SphereDef& s : spheres) {
    const Affine<double> m = scene.objects[s.object].motion->at(0);
    const Vec3d c0 = m.point(s.local.c);
    const double r = s.local.r * max_stretch(m);
    for (int a = 0; a < 3; ++a) {
      Vec3d d(0);
      d[a] = r;
      extremes.push_back(c0 + d);
      extremes.push_back(c0 - d);
    }
  }
  const double bound = minimal_sphere(extremes).r;
  const double area = 4 * 3.14159265358979323846 * bound * bound;
  std::vector<double> w;
  w.reserve(spheres.size());
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SphereDef& s = spheres[i];
    if (c.bvh.empty()) {
      w.push_back(c.sphere + s.surface_area() / area * (c.transform + static_cast<double>(s.prims.size()) * c.triangle));
      continue;
    }
    double entered = s.surface_area() * (c.transform + c.box_setup + c.box);  // area x cycles
    for (const NodeArea& n : c.bvh.at(i))
      entered += n.area * (n.triangles ? n.triangles * c.triangle : 2 * c.box);
    w.push_back(c.sphere + entered / area);
  }
  return w;
}

Assignment static_assignment(const std::string& policy, const Scene& scene, const std::vector<SphereDef>& spheres,
                             std::size_t units, const SaNCosts& costs) {
  if (policy == "paper") return assign_paper(spheres.size(), units);
  if (policy == "round_robin") return assign_round_robin(spheres.size(), units);
  if (policy == "sa_n") return assign_weighted(sa_n_weights(scene, spheres, costs), units);
  throw std::invalid_argument("static_assignment: policy " + policy + " is not static");
}

}  // namespace oprt
