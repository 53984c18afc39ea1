#include "scene/scene.h"

#include <algorithm>
#include <cmath>

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

Vec3d unit_or_zero(const Vec3d& n) {
  const double len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  return len > 0 && std::isfinite(len) ? n / len : Vec3d(0);
}

Vec3d transform_normal(const Affine<double>& a, const Vec3d& n) {
  // The cofactor matrix of L is det(L) L^-T: the same direction as the inverse transpose up
  // to det's sign, without a division.
  const auto& m = a.m;
  double c[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      c[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
    }
  const double det = m[0][0] * c[0][0] + m[0][1] * c[0][1] + m[0][2] * c[0][2];
  const double s = det < 0 ? -1.0 : 1.0;
  const Vec3d r{s * (c[0][0] * n.x + c[0][1] * n.y + c[0][2] * n.z), s * (c[1][0] * n.x + c[1][1] * n.y + c[1][2] * n.z),
                s * (c[2][0] * n.x + c[2][1] * n.y + c[2][2] * n.z)};
  return unit_or_zero(r);
}

std::size_t Mesh::triangles_with_normals() const {
  std::size_t n = 0;
  for (std::size_t t = 0; t < normal_index.size(); ++t) n += has_normals(t);
  return n;
}

void Mesh::append(const Mesh& other, const Affine<double>& placed) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  const std::size_t old_triangles = triangles.size();
  for (const Vec3d& v : other.vertices) vertices.push_back(placed.point(v));
  for (const Tri& t : other.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  if (other.normal_index.empty() && normal_index.empty()) return;
  constexpr Tri none{kNoNormal, kNoNormal, kNoNormal};
  normal_index.resize(old_triangles, none);  // this mesh had none so far: its triangles are flat
  if (other.normal_index.empty()) {
    normal_index.resize(triangles.size(), none);
    return;
  }
  bool identity = true;
  const Affine<double> id = Affine<double>::identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) identity = identity && placed.m[i][j] == id.m[i][j];
  const auto nbase = static_cast<std::uint32_t>(normals.size());
  for (const Vec3d& n : other.normals) normals.push_back(identity ? n : transform_normal(placed, n));
  for (const Tri& t : other.normal_index)
    normal_index.push_back(t[0] == kNoNormal ? none : Tri{t[0] + nbase, t[1] + nbase, t[2] + nbase});
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const Object& o : objects) n += o.mesh.triangles.size();
  return n;
}

}  // namespace oprt
