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
double watertight_t_error(const Vec3d& o, const Vec3d& d, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2,
                          bool unit_direction) {
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
  // pbrt bounds the error of x' = a_x + sx a_z by gamma_5 (max |x'| + max |z'|), using |sx a_z|
  // <= |a_z| <= |sz a_z| = |z'|, which holds for a unit direction. The local direction is not
  // one (the local ray keeps the world parameter: under a map scaled by 1e3 it is 1e-3 long),
  // and then |z'| = |a_z| / |d_z| exceeds |sx a_z| by 1 / |d|: for a long sliver seen along
  // its length the bound, and with it the offset, grew 1e3-fold (tests/numerics, "closed
  // meshes": reflection origins pushed out through the thin cylinder, 0.1 across in its own
  // coordinates, under the map scaled by 1e3). The terms themselves,
  // |sx a_z| and |sy a_z| (twice: |a_x| <= |x'| + |sx a_z|), bound the same rounding.
  double max_sxz = 0, max_syz = 0;
  for (int i = 0; i < 3; ++i) {
    const double az_i = (*v[i] - o)[kz];
    max_sxz = std::max(max_sxz, std::fabs(sx * az_i));
    max_syz = std::max(max_syz, std::fabs(sy * az_i));
  }
  const double delta_z = gamma<T>(3) * max_z;
  const double delta_x = gamma<T>(5) * (max_x + (unit_direction ? max_z : 2 * max_sxz));
  const double delta_y = gamma<T>(5) * (max_y + (unit_direction ? max_z : 2 * max_syz));
  const double delta_e = 2 * (gamma<T>(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
  return 3 * (gamma<T>(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) / std::fabs(det);
}

template <typename T>
Vec3d offset_origin(Kernel kernel, const Vec3d& p, const Vec3d& n, const Vec3d& l, const Placement& pl,
                    const Vec3d& v0, const Vec3d& v1, const Vec3d& v2, OffsetBound bound) {
  // The IU decides which side of the plane the origin lies on from t det = (o' - v0).n in
  // T, where o' = to_local(o) is computed in T (every coordinate rounded up to a few ulps of
  // the magnitudes |L^-1| |o| + |t^-1|), and v0, e1, e2, n are the T-rounded triangle
  // (an ulp of the vertex magnitudes). The plane distance so evaluated errs by a few ulps of
  // those magnitudes, in local units; the largest stretch of to_world turns that into world
  // units. A further few ulps of |p| cover rounding the origin itself to T. The factor 16
  // is the safety the count of roundings (at most 8 in any chain above) asks for, doubled.
  //
  // That bound is isotropic: it charges every local axis the largest magnitude and stretches
  // the result by to_world's largest stretch. Under an anisotropic map (an object scaled by
  // 1, 1e-2, 1e2) both maxima come from different axes, and the bound exceeds the error by
  // up to the map's condition number (1e4): in float it pushed refraction origins out through
  // the far side of the flattened sphere, and mirrors' origins past the mirror facing them
  // (tests/numerics, "glass sphere", "facing mirrors": overshoots, lost bounces). The same
  // roundings bounded per axis: local coordinate i errs by at most 16 eps e_i, e_i =
  // sum_j |L^-1_ij| |o_j| + |t^-1_i| + the vertex magnitudes; that error vector, carried by
  // to_world's linear part M, moves the point along the world normal n by at most
  // sum_k |n_k| sum_i |M_ki| e_i (and rounding o to T by sum_k |n_k| |o_k|). Both are bounds
  // on the same error, so the smaller one may be kept (OffsetBound, shading.h: for a rigid
  // map they are within a small factor of each other).
  const double eps = std::numeric_limits<T>::epsilon();
  const double vertex_mag = std::max({max_abs_component(v0), max_abs_component(v1), max_abs_component(v2)}) +
                            std::max(max_abs_component(v1 - v0), max_abs_component(v2 - v0));
  const double local_mag = row_sum_norm(pl.to_local) * max_abs_component(p) +
                           max_abs_component(pl.to_local.translation()) + vertex_mag;
  const double isotropic = max_stretch(pl.to_world) * local_mag + max_abs_component(p);
  double e[3];
  for (int i = 0; i < 3; ++i)
    e[i] = std::fabs(pl.to_local.m[i][0] * p.x) + std::fabs(pl.to_local.m[i][1] * p.y) +
           std::fabs(pl.to_local.m[i][2] * p.z) + std::fabs(pl.to_local.m[i][3]) + vertex_mag;
  double per_axis = 0;
  for (int k = 0; k < 3; ++k)
    per_axis += std::fabs(n[k]) * (std::fabs(pl.to_world.m[k][0]) * e[0] + std::fabs(pl.to_world.m[k][1]) * e[1] +
                                   std::fabs(pl.to_world.m[k][2]) * e[2] + std::fabs(p[k]));
  const bool tight = bound == OffsetBound::tightest;
  double d = 16 * eps * (tight ? std::min(isotropic, per_axis) : isotropic);
  if (kernel == Kernel::watertight) {
    // The watertight test computes t = T / D from edge functions whose rounding errors do
    // not cancel against the plane distance as Moller's (o' - v0).n does: for a sliver or a
    // ray grazing the plane its t errs by more. The own triangle is met at t = -h / cos,
    // h the offset and cos = n.l; pushing h beyond cos times twice the kernel's bound on
    // t's error keeps that t negative. (The bound is in world units: a local ray keeps the
    // world parameter.)
    const Vec3d o_local = pl.to_local.point(p), d_local = pl.to_local.vector(l);
    d += 2 * dot3(n, l) * watertight_t_error<T>(o_local, d_local, v0, v1, v2, !tight);
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

namespace {
// The inverse transpose (L^-1)^T n: how a normal goes from local to world coordinates.
Vec3d normal_to_world(const Placement& pl, const Vec3d& nl) {
  const auto& li = pl.to_local.m;
  return {li[0][0] * nl.x + li[1][0] * nl.y + li[2][0] * nl.z, li[0][1] * nl.x + li[1][1] * nl.y + li[2][1] * nl.z,
          li[0][2] * nl.x + li[1][2] * nl.y + li[2][2] * nl.z};
}
}  // namespace

SurfacePoint surface_point(const Object& obj, const Placement& pl, std::uint32_t prim, double u, double v) {
  const Tri& tri = obj.mesh.triangles[prim];
  SurfacePoint s;
  s.a = obj.mesh.vertices[tri[0]];
  s.b = obj.mesh.vertices[tri[1]];
  s.c = obj.mesh.vertices[tri[2]];
  s.p = pl.to_world.point(s.a + (s.b - s.a) * u + (s.c - s.a) * v);
  s.n = glm::normalize(normal_to_world(pl, cross3(s.b - s.a, s.c - s.a)));
  s.shading = s.n;
  if (obj.mesh.has_normals(prim)) {  // the published normals, interpolated (Phong 1975)
    const Tri& ni = obj.mesh.normal_index[prim];
    const Vec3d nl = obj.mesh.normals[ni[0]] * (1 - u - v) + obj.mesh.normals[ni[1]] * u + obj.mesh.normals[ni[2]] * v;
    const Vec3d nw = normal_to_world(pl, nl);
    if (dot3(nw, nw) > 0) s.shading = glm::normalize(nw);
  }
  return s;
}

template <typename T>
Vec3d Shader<T>::shade(const Ray<T>& ray, const HitRecord<T>& hit, int depth, bool inside,
                       std::vector<SpawnedRay<T>>& out) const {
  const Object& obj = scene_.objects[hit.object];
  const Material& mat = scene_.materials[obj.material];
  const Placement& pl = frame_.placement[hit.object];
  const SurfacePoint sp = surface_point(obj, pl, hit.prim, hit.u, hit.v);
  const Vec3d& p = sp.p;
  const Vec3d view = -glm::normalize(Vec3d(ray.d));
  // Two-sided: shade the side the ray sees. The geometric normal nf decides which lights
  // face the surface and which side a spawned ray leaves from (so that no ray starts behind
  // its own triangle); the shading normal ns, turned the same way, gives the light's terms
  // and the secondary rays' directions. Without published normals ns is nf, bit for bit.
  const Vec3d nf = dot3(sp.n, view) < 0 ? -sp.n : sp.n;
  const Vec3d ns = dot3(sp.shading, nf) < 0 ? -sp.shading : sp.shading;
  for (const PointLight& light : frame_.lights) {
    const Vec3d to_light = light.position - p;
    const double dist = std::sqrt(dot3(to_light, to_light));
    if (!(dist > 0)) continue;
    const Vec3d l = to_light / dist;
    if (!(dot3(nf, l) > 0)) continue;  // light behind the surface: unlit, no ray needed
    const double cos_l = std::max(0.0, dot3(ns, l));
    const Vec3d r = ns * (2 * cos_l) - l;
    const double spec = std::pow(std::max(0.0, dot3(r, view)), mat.shininess);
    const Vec3d origin = offset_origin<T>(frame_.kernel, p, nf, l, pl, sp.a, sp.b, sp.c, OffsetBound::isotropic);
    const Vec3d d = light.position - origin;
    const double len = std::sqrt(dot3(d, d));
    out.push_back({{Vec3<T>(origin), Vec3<T>(d / len), static_cast<T>(len)},
                   RayKind::shadow,
                   (mat.diffuse * cos_l + mat.specular * spec) * light.color,
                   inside});
  }
  if (depth < depth_) spawn_secondary(ray, sp, nf, ns, mat, pl, inside, out);
  return scene_.ambient * mat.diffuse;
}

// The reflection ray, R = D - 2 (D.N) N, and the refraction ray by Snell's law, with eta the
// ratio of the indices on the two sides (1 / ior entering the object, ior leaving it: the ray
// knows whether it travels inside; nested media are not tracked):
//   T = eta D + (eta cos_i - sqrt(k)) N,  k = 1 - eta^2 (1 - cos_i^2),  cos_i = -D.N.
// k < 0 is total internal reflection: no light leaves, and the transmitted share follows the
// reflected direction (one reflection ray carries both weights). N is the shading normal
// unless it would send the ray to the wrong side of the triangle (a grazing ray on a curved
// mesh): then the geometric one.
template <typename T>
void Shader<T>::spawn_secondary(const Ray<T>& ray, const SurfacePoint& sp, const Vec3d& nf, const Vec3d& ns,
                                const Material& mat, const Placement& pl, bool inside,
                                std::vector<SpawnedRay<T>>& out) const {
  const Vec3d d = glm::normalize(Vec3d(ray.d));
  auto emit = [&](RayKind kind, Vec3d dir, const Vec3d& side, const Vec3d& weight, bool in) {
    dir = glm::normalize(dir);
    const Vec3d origin = offset_origin<T>(frame_.kernel, sp.p, side, dir, pl, sp.a, sp.b, sp.c);
    out.push_back({{Vec3<T>(origin), Vec3<T>(dir), kInf<T>}, kind, weight, in});
  };
  auto reflected = [&](const Vec3d& n) { return d - n * (2 * dot3(d, n)); };
  Vec3d reflect = mat.reflect;
  Vec3d transmitted{0};
  bool refracts = false;
  if (mat.transmits()) {
    const double eta = inside ? mat.ior : 1 / mat.ior;
    Vec3d n = ns;
    double cos_i = -dot3(d, n);
    const double k = 1 - eta * eta * (1 - cos_i * cos_i);
    if (k < 0) {
      reflect += mat.transmit;  // total internal reflection
    } else {
      transmitted = d * eta + n * (eta * cos_i - std::sqrt(k));
      if (!(dot3(transmitted, nf) < 0)) {  // bent back by the shading normal: the geometric one
        n = nf;
        cos_i = -dot3(d, n);
        transmitted = d * eta + n * (eta * cos_i - std::sqrt(std::max(0.0, 1 - eta * eta * (1 - cos_i * cos_i))));
      }
      refracts = dot3(transmitted, nf) < 0;
      if (!refracts) reflect += mat.transmit;  // grazing: nothing crosses
    }
  }
  if (reflect.x > 0 || reflect.y > 0 || reflect.z > 0) {
    Vec3d r = reflected(ns);
    if (!(dot3(r, nf) > 0)) r = reflected(nf);
    emit(RayKind::reflection, r, nf, reflect, inside);
  }
  if (refracts) emit(RayKind::refraction, transmitted, -nf, mat.transmit, !inside);
}

template class Shader<float>;
template class Shader<double>;
template Vec3d offset_origin<float>(Kernel, const Vec3d&, const Vec3d&, const Vec3d&, const Placement&, const Vec3d&,
                                    const Vec3d&, const Vec3d&, OffsetBound);
template Vec3d offset_origin<double>(Kernel, const Vec3d&, const Vec3d&, const Vec3d&, const Placement&, const Vec3d&,
                                     const Vec3d&, const Vec3d&, OffsetBound);
template double watertight_t_error<float>(const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, bool);
template double watertight_t_error<double>(const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, const Vec3d&, bool);

}  // namespace oprt
