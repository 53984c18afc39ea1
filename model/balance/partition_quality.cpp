#include "balance/partition_quality.h"

#include <algorithm>

namespace oprt {

std::vector<Box<double>> sphere_world_boxes(const Scene& scene, const std::vector<SphereDef>& spheres, int frame) {
  std::vector<std::vector<Vec3d>> world(scene.objects.size());  // per object, filled when first needed
  std::vector<Box<double>> out;
  out.reserve(spheres.size());
  for (const SphereDef& d : spheres) {
    std::vector<Vec3d>& v = world.at(d.object);
    if (v.empty()) {
      const Object& o = scene.objects[d.object];
      if (o.deform) o.deform->at(frame, v);
      else v = o.mesh.vertices;
      const Affine<double> m = o.motion->at(frame);
      for (Vec3d& p : v) p = m.point(p);
    }
    Box<double> b;
    for (std::uint32_t t : d.prims)
      for (std::uint32_t k : scene.objects[d.object].mesh.triangles[t]) b.extend(v[k]);
    out.push_back(b);
  }
  return out;
}

std::vector<Box<double>> unit_bounds(const Assignment& a, const std::vector<Box<double>>& sphere_box) {
  std::vector<Box<double>> out(a.units());
  for (std::size_t u = 0; u < a.units(); ++u)
    for (std::uint32_t s : a.unit[u])
      if (!sphere_box.at(s).empty()) out[u].extend(sphere_box[s]);
  return out;
}

Box<double> union_of(const std::vector<Box<double>>& boxes) {
  Box<double> all;
  for (const Box<double>& b : boxes)
    if (!b.empty()) all.extend(b);
  return all;
}

double expected_fanout(const std::vector<Box<double>>& unit_bound, const Box<double>& scene) {
  const double area = scene.surface_area();
  double sum = 0;
  for (const Box<double>& b : unit_bound)
    if (!b.empty()) sum += area > 0 ? b.surface_area() / area : 1;
  return sum;
}

double load_imbalance(const std::vector<double>& unit_load) {
  if (unit_load.empty()) return 1;
  double total = 0, most = 0;
  for (double l : unit_load) total += l, most = std::max(most, l);
  return total > 0 ? most * static_cast<double>(unit_load.size()) / total : 1;
}

PartitionQuality partition_quality(const Assignment& a, const std::vector<Box<double>>& sphere_box,
                                   const std::vector<double>& weight) {
  PartitionQuality q;
  q.unit_bound = unit_bounds(a, sphere_box);
  q.scene_bound = union_of(sphere_box);
  q.unit_load = unit_loads(a, weight);
  q.fanout = expected_fanout(q.unit_bound, q.scene_bound);
  q.imbalance = load_imbalance(q.unit_load);
  return q;
}

}  // namespace oprt
