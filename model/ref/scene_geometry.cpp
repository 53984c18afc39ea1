#include "ref/scene_geometry.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oprt {

template <typename T>
SceneGeometry<T> build_geometry(const Scene& scene, std::vector<SphereDef> defs) {
  SceneGeometry<T> g;
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
    g.first.push_back(static_cast<std::uint32_t>(g.tris.size()));
    // The stored vertices are rounded to T; the sphere must enclose the rounded ones.
    double r = d.local.r;
    for (std::uint32_t p : d.prims) {
      const Tri& t = m.triangles[p];
      const Vec3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
      g.tris.push_back(prepare_moller<T>(a, b, c));
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

template SceneGeometry<float> build_geometry(const Scene&, std::vector<SphereDef>);
template SceneGeometry<double> build_geometry(const Scene&, std::vector<SphereDef>);

}  // namespace oprt
