#include "balance/policy.h"

#include "balance/hull_area.h"
#include "balance/partition_quality.h"
#include "geom/bounding_sphere.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oprt {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Fraction of the directions around p that a sphere covers (1 if p is inside it).
double cap_fraction(const Vec3d& p, const Vec3d& c, double r) {
  const Vec3d to = c - p;
  const double d2 = dot3(to, to);
  if (d2 <= r * r) return 1;
  return (1 - std::sqrt(1 - r * r / d2)) / 2;
}
}  // namespace

std::vector<double> sa_n_weights(const Scene& scene, const std::vector<SphereDef>& spheres, const SaNCosts& c) {
  const double hull = scene_hull_area(scene);
  const double lights = static_cast<double>(scene.lights.size());
  std::vector<double> w;
  w.reserve(spheres.size());
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SphereDef& s = spheres[i];
    const Vec3d centre = scene.objects[s.object].motion->at(0).point(s.local.c);
    const double r = s.world_radius();
    double entering = std::min(1.0, 4 * kPi * r * r / hull);
    for (const PointLight& l : scene.lights) entering += cap_fraction(l.position, centre, r);
    double entry = c.transform + static_cast<double>(s.prims.size()) * c.triangle;
    if (!c.bvh.empty()) {
      entry = c.transform + c.box_setup + c.box;
      // Node boxes are in local units: the ratio needs the sphere's local area.
      const double area = std::max(4 * kPi * s.local.r * s.local.r, 1e-300);
      for (const NodeArea& n : c.bvh.at(i))
        entry += n.area / area * (n.triangles ? n.triangles * c.triangle : 2 * c.box);
    }
    w.push_back((1 + lights) * c.sphere + entering * entry);
  }
  return w;
}

Assignment static_assignment(const std::string& policy, const Scene& scene, const std::vector<SphereDef>& spheres,
                             std::size_t units, const SaNCosts& costs, double locality) {
  if (policy == "paper") return assign_paper(spheres.size(), units);
  if (policy == "round_robin") return assign_round_robin(spheres.size(), units);
  if (policy == "sa_n") return assign_weighted(sa_n_weights(scene, spheres, costs), units);
  if (policy == "spatial")
    return assign_spatial(sphere_world_boxes(scene, spheres, 0), sa_n_weights(scene, spheres, costs), units, locality);
  throw std::invalid_argument("static_assignment: policy " + policy + " is not static");
}

Assignment initial_assignment(const std::string& policy, std::optional<double> locality, const Scene& scene,
                              const std::vector<SphereDef>& spheres, std::size_t units, const SaNCosts& costs) {
  if (policy == "spatial") return static_assignment(policy, scene, spheres, units, costs, locality.value_or(kDefaultLocality));
  if (policy == "feedback" && locality) return static_assignment("spatial", scene, spheres, units, costs, *locality);
  if (policy == "feedback" || policy == "view") return static_assignment("sa_n", scene, spheres, units, costs);
  return static_assignment(policy, scene, spheres, units, costs);
}

}  // namespace oprt
