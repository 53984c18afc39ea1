#include "ref/shading.h"

#include <algorithm>
#include <cmath>

namespace oprt {

namespace {
double row_sum_norm(const Affine<double>& a) {  // infinity norm of the linear part
  double n = 0;
  for (int i = 0; i < 3; ++i)
    n = std::max(n, std::fabs(a.m[i][0]) + std::fabs(a.m[i][1]) + std::fabs(a.m[i][2]));
  return n;
}
}  // namespace

template <typename T>
double watertight_t_error(const Vec3d& o, const Vec3d& d, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
  const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  const int kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
  const int kx = kz == 2 ? 0 : kz + 1, ky = kx == 2 ? 0 : kx + 1;
  const double sx = -d[kx] / d[kz], sy = -d[ky] / d[kz], sz = 1 / d[kz];
  double xt[3], yt[3], zt[3];
  const Vec3d* v[3] = {&v0, &v1, &v2};
  for (int i = 0; i < 3; ++i) {
    const Vec3d a = *v[i] - o;
    xt[i] = a[kx] + sx * a[kz];
    yt[i] = a[ky] + sy * a[kz];
    zt[i] = sz * a[kz];
  }
  const double e0 = xt[1] * yt[2] - yt[1] * xt[2], e1 = xt[2] * yt[0] - yt[2] * xt[0],
               e2 = xt[0] * yt[1] - yt[0] * xt[1];
  const double det = e0 + e1 + e2;
  if (!(std::fabs(det) > 0)) return 0;
  const double max_x = std::max({std::fabs(xt[0]), std::fabs(xt[1]), std::fabs(xt[2])});
  const double max_y = std::max({std::fabs(yt[0]), std::fabs(yt[1]), std::fabs(yt[2])});
  const double max_z = std::max({std::fabs(zt[0]), std::fabs(zt[1]), std::fabs(zt[2])});
  const double max_e = std::max({std::fabs(e0), std::fabs(e1), std::fabs(e2)});
  const double delta_z = gamma<T>(3) * max_z;
  const double delta_x = gamma<T>(5) * (max_x + max_z), delta_y = gamma<T>(5) * (max_y + max_z);
  const double delta_e = 2 * (gamma<T>(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
  return 3 * (gamma<T>(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) / std::fabs(det);
}

template <typename T>
Vec3d offset_origin(Kernel kernel, const Vec3d& p, const Vec3d& n, const Vec3d& l, const Placement& pl,
                    const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
  // The IU decides which side of the plane the origin lies on from t det = (o' - v0).n in
  // T, where o' = to_local(o) is computed in T (every coordinate rounded up to a few ulps of
  // the magnitudes |L^-1| |o| + |t^-1|), and v0, e1, e2, n are the T-rounded triangle
  // (an ulp of the vertex magnitudes). The plane distance so evaluated errs by a few ulps of
  // those magnitudes, in local units; the largest stretch of to_world turns that into world
  // units. A further few ulps of |p| cover rounding the origin itself to T. The factor 16
  // is the safety the count of roundings (at most 8 in any chain above) asks for, doubled.
  const double eps = std::numeric_limits<T>::epsilon();
  const double local_mag = row_sum_norm(pl.to_local) * max_abs_component(p) +
                           max_abs_component(pl.to_local.translation()) +
                           std::max({max_abs_component(v0), max_abs_component(v1), max_abs_component(v2)}) +
                           std::max(max_abs_component(v1 - v0), max_abs_component(v2 - v0));
  double d = 16 * eps * (max_stretch(pl.to_world) * local_mag + max_abs_component(p));
  if (kernel == Kernel::watertight) {
    // The watertight test computes t = T / D from edge functions whose rounding errors do
    // not cancel against the plane distance as Moller's (o' - v0).n does: for a sliver or a
    // ray grazing the plane its t errs by more. The own triangle is met at t = -h / cos,
    // h the offset and cos = n.l; pushing h beyond cos times twice the kernel's bound on
    // t's error keeps that t negative. (The bound is in world units: a local ray keeps the
    // world parameter.)
    const Vec3d o_local = pl.to_local.point(p), d_local = pl.to_local.vector(l);
    d += 2 * dot3(n, l) * watertight_t_error<T>(o_local, d_local, v0, v1, v2);
  }
  Vec3d o = p + n * d;
  // Rounding o to T must not undo the offset: round each coordinate away from the surface.
  for (int i = 0; i < 3; ++i) {
    const T r = static_cast<T>(o[i]);
    if (n[i] > 0 && static_cast<double>(r) < o[i]) o[i] = std::nextafter(r, kInf<T>);
    else if (n[i] < 0 && static_cast<double>(r) > o[i]) o[i] = std::nextafter(r, -kInf<T>);
    else o[i] = r;
  }
  return o;
}

SurfacePoint surface_point(const Object& obj, const Placement& pl, std::uint32_t prim, double u, double v) {
  const Tri& tri = obj.mesh.triangles[prim];
  SurfacePoint s;
  s.a = obj.mesh.vertices[tri[0]];
  s.b = obj.mesh.vertices[tri[1]];
  s.c = obj.mesh.vertices[tri[2]];
  s.p = pl.to_world.point(s.a + (s.b - s.a) * u + (s.c - s.a) * v);
  // Normals transform by the inverse transpose: n_world = (L^-1)^T n_local.
  const Vec3d nl = cross3(s.b - s.a, s.c - s.a);
  const auto& li = pl.to_local.m;
  const Vec3d n{li[0][0] * nl.x + li[1][0] * nl.y + li[2][0] * nl.z,
                li[0][1] * nl.x + li[1][1] * nl.y + li[2][1] * nl.z,
                li[0][2] * nl.x + li[1][2] * nl.y + li[2][2] * nl.z};
  s.n = glm::normalize(n);
  return s;
}

template <typename T>
ShadeState<T> Shader<T>::prepare(const Ray<T>& primary, const HitRecord<T>& hit,
                                 std::vector<Ray<T>>& shadow) const {
  ShadeState<T> s;
  const Object& obj = scene_.objects[hit.object];
  const Material& mat = scene_.materials[obj.material];
  const Placement& pl = frame_.placement[hit.object];
  const SurfacePoint sp = surface_point(obj, pl, hit.prim, hit.u, hit.v);
  const Vec3d &p = sp.p, &a = sp.a, &b = sp.b, &c = sp.c;
  Vec3d n = sp.n;
  const Vec3d view = -glm::normalize(Vec3d(primary.d));
  if (dot3(n, view) < 0) n = -n;  // two-sided: shade the side the ray sees
  s.color = scene_.ambient * mat.diffuse;
  for (const PointLight& light : frame_.lights) {
    const Vec3d to_light = light.position - p;
    const double dist = std::sqrt(dot3(to_light, to_light));
    if (!(dist > 0)) continue;
    const Vec3d l = to_light / dist;
    const double cos_l = dot3(n, l);
    if (!(cos_l > 0)) continue;  // light behind the surface: unlit, no ray needed
    const Vec3d r = n * (2 * cos_l) - l;
    const double spec = std::pow(std::max(0.0, dot3(r, view)), mat.shininess);
    s.light_term.push_back((mat.diffuse * cos_l + mat.specular * spec) * light.color);
    const Vec3d origin = offset_origin<T>(frame_.kernel, p, n, l, pl, a, b, c);
    const Vec3d d = light.position - origin;
    const double len = std::sqrt(dot3(d, d));
    shadow.push_back({Vec3<T>(origin), Vec3<T>(d / len), static_cast<T>(len)});
  }
  return s;
}

template <typename T>
Vec3d Shader<T>::finish(const ShadeState<T>& s, const std::uint8_t* occluded) const {
  Vec3d c = s.color;
  for (std::size_t i = 0; i < s.light_term.size(); ++i)
    if (!occluded[i]) c += s.light_term[i];
  return c;
}

template class Shader<float>;
template class Shader<double>;
template Vec3d offset_origin<float>(Kernel, const Vec3d&, const Vec3d&, const Vec3d&, const Placement&, const Vec3d&,
                                    const Vec3d&, const Vec3d&);
template Vec3d offset_origin<double>(Kernel, const Vec3d&, const Vec3d&, const Vec3d&, const Placement&, const Vec3d&,
                                     const Vec3d&, const Vec3d&);
template double watertight_t_error<float>(const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&);
template double watertight_t_error<double>(const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&);

}  // namespace oprt
