#include "ref/scene_geometry.h"

#include "geom/bounding_sphere.h"
#include "scene/error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oprt {

namespace {
// The sphere enclosing triangles as stored in T, rounded up (see build_geometry).
template <typename T>
Sphere<T> enclosing(const Sphere<double>& minimal, const std::vector<Vec3d>& stored) {
  double r = minimal.r;
  Sphere<T> s;
  s.c = Vec3<T>(minimal.c);
  for (const Vec3d& v : stored) {
    const Vec3d d = v - minimal.c;
    r = std::fmax(r, std::sqrt(dot3(d, d)));
  }
  const Vec3d shift = Vec3d(s.c) - minimal.c;
  r += std::sqrt(dot3(shift, shift));
  s.r = static_cast<T>(r);
  if (static_cast<double>(s.r) < r) s.r = std::nextafter(s.r, kInf<T>);
  return s;
}

// A triangle whose data is finite in double but not in T (a coordinate, an edge or the
// normal beyond float's range) would put infinities into the kernels: refuse it.
template <typename T>
void check_fits(const Scene& scene, std::uint32_t object, std::uint32_t prim, const TriangleStore<T>& tris,
                std::size_t i) {
  if (tris.finite(i)) return;
  throw InputError(scene.source,
                   "object " + std::to_string(object) + " (\"" + scene.objects[object].name + "\") triangle " +
                       std::to_string(prim),
                   std::string("vertex coordinates, edges or normal beyond the range of ") +
                       (sizeof(T) == 4 ? "float" : "double") + " precision");
}
}  // namespace

bool has_deforming(const Scene& scene) {
  for (const Object& o : scene.objects)
    if (o.deform) return true;
  return false;
}

template <typename T>
std::uint64_t update_deforming(SceneGeometry<T>& g, const Scene& scene, int frame) {
  std::uint64_t bytes = 0;
  std::vector<Vec3d> verts, stored;
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s) {
    if (!g.deforming[s]) continue;
    const Object& obj = scene.objects[g.object[s]];
    obj.deform->at(frame, verts);
    stored.clear();
    std::vector<Vec3d> points;
    for (std::uint32_t k = g.first[s]; k < g.first[s + 1]; ++k) {
      const Tri& t = obj.mesh.triangles[g.prim[k]];
      g.tris.write(k, verts[t[0]], verts[t[1]], verts[t[2]]);
      check_fits(scene, g.object[s], g.prim[k], g.tris, k);
      for (std::uint32_t v : t) {
        points.push_back(verts[v]);
        stored.push_back(Vec3d(Vec3<T>(verts[v])));
      }
    }
    g.local_sphere[s] = enclosing<T>(minimal_sphere(points), stored);
    bytes += static_cast<std::uint64_t>(g.triangles_in(s)) * g.triangle_bytes();
  }
  return bytes;
}

template <typename T>
SceneGeometry<T> build_geometry(const Scene& scene, std::vector<SphereDef> defs, Kernel kernel) {
  SceneGeometry<T> g;
  g.tris = TriangleStore<T>(kernel);
  std::size_t total = 0;
  for (const SphereDef& d : defs) total += d.prims.size();
  g.tris.reserve(total);
  g.prim.reserve(total);
  for (const SphereDef& d : defs) {
    const Mesh& m = scene.objects[d.object].mesh;
    // Ascending prims: then the first of equal-t hits in memory order is the lowest prim,
    // the tie-break of traverse.h.
    if (!std::is_sorted(d.prims.begin(), d.prims.end()))
      throw std::logic_error("build_geometry: sphere primitives must be in ascending order");
    g.object.push_back(d.object);
    g.deforming.push_back(scene.objects[d.object].deform ? 1 : 0);
    g.first.push_back(static_cast<std::uint32_t>(g.tris.size()));
    // The stored vertices are rounded to T; the sphere must enclose the rounded ones.
    double r = d.local.r;
    for (std::uint32_t p : d.prims) {
      const Tri& t = m.triangles[p];
      const Vec3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
      g.tris.push_back(a, b, c);
      check_fits(scene, d.object, p, g.tris, g.tris.size() - 1);
      g.prim.push_back(p);
      for (const Vec3d& v : {a, b, c}) {
        const Vec3d vt = Vec3d(Vec3<T>(v)) - d.local.c;
        r = std::fmax(r, std::sqrt(dot3(vt, vt)));
      }
    }
    Sphere<T> s;
    s.c = Vec3<T>(d.local.c);
    // Centre rounding moves the centre by up to half an ulp per coordinate: add it, and
    // round the radius up, so the T sphere still encloses every T vertex.
    const Vec3d shift = Vec3d(s.c) - d.local.c;
    r += std::sqrt(dot3(shift, shift));
    s.r = static_cast<T>(r);
    if (static_cast<double>(s.r) < r) s.r = std::nextafter(s.r, kInf<T>);
    g.local_sphere.push_back(s);
  }
  g.first.push_back(static_cast<std::uint32_t>(g.tris.size()));
  g.defs = std::move(defs);
  return g;
}

template SceneGeometry<float> build_geometry(const Scene&, std::vector<SphereDef>, Kernel);
template SceneGeometry<double> build_geometry(const Scene&, std::vector<SphereDef>, Kernel);
template std::uint64_t update_deforming(SceneGeometry<float>&, const Scene&, int);
template std::uint64_t update_deforming(SceneGeometry<double>&, const Scene&, int);

}  // namespace oprt
