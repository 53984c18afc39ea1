#include "scene/scene.h"

#include <algorithm>

namespace oprt {

Camera KeyframeCamera::at(double frame) const {
  if (keys_.empty()) return {};
  if (frame <= keys_.front().frame) return keys_.front().camera;
  if (frame >= keys_.back().frame) return keys_.back().camera;
  auto hi = std::upper_bound(keys_.begin(), keys_.end(), frame,
                             [](double f, const CameraKey& k) { return f < k.frame; });
  const Camera& a = (hi - 1)->camera;
  const Camera& b = hi->camera;
  const double s = (frame - (hi - 1)->frame) / (hi->frame - (hi - 1)->frame);
  Camera c;
  c.eye = a.eye + (b.eye - a.eye) * s;
  c.target = a.target + (b.target - a.target) * s;
  c.up = a.up + (b.up - a.up) * s;
  c.fov_y_deg = a.fov_y_deg + (b.fov_y_deg - a.fov_y_deg) * s;
  return c;
}

void Mesh::append(const Mesh& other, const Affine<double>& placed) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  for (const Vec3d& v : other.vertices) vertices.push_back(placed.point(v));
  for (const Tri& t : other.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const Object& o : objects) n += o.mesh.triangles.size();
  return n;
}

}  // namespace oprt
