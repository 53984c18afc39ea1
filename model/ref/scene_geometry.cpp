#include "ref/scene_geometry.h"

#include "geom/bounding_sphere.h"
#include "base/error.h"

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

// How far a sphere's node boxes reach beyond its triangles' exact bounds. The box test is
// conservative for the exact ray and the exact box (geom/bvh.h, kBoxSlack), but a triangle
// kernel decides in floating point: it can accept a ray that, exactly, passes just outside
// the triangle, or place the hit a little before where the exact ray meets it (its t is
// rounded), and the kernel stores its own rounding of the vertices (v0 + e1 is not v1).
// BVH and brute force then agree only if the boxes also hold the points the kernel may
// report. The kernels' errors are a few ulps of the distances involved: for a hit at
// distance D from the ray origin the kernel's t is off by about gamma(6) D along the ray
// (Moller: t = (tv.n) / det, each a 3-term dot product), and a box padded by `pad` is
// entered at least pad / |d| earlier than the triangle surface it holds (the exact ray
// crosses the padding first). The first term covers hits up to ~1000 sphere radii away
// (8192 u r against ~8 u D), the second the kernels' vertex roundings (a few u of the
// coordinates' magnitude). Cost: a float box grows by 5e-4 of the sphere's radius.
template <typename T>
double bvh_pad(double radius, double magnitude) {
  return 8192 * unit_roundoff<T>() * radius + 8 * unit_roundoff<T>() * magnitude;
}

// Bounds of the triangles [first, end) of g (their mesh vertices, exact in double) and the
// largest vertex coordinate magnitude.
template <typename T>
std::vector<Box<double>> triangle_bounds(const SceneGeometry<T>& g, const Mesh& mesh, const std::vector<Vec3d>& verts,
                                         std::uint32_t first, std::uint32_t end, double& magnitude) {
  std::vector<Box<double>> b(end - first);
  for (std::uint32_t k = first; k < end; ++k)
    for (std::uint32_t v : mesh.triangles[g.prim[k]]) {
      b[k - first].extend(verts[v]);
      magnitude = std::fmax(magnitude, max_abs_component(verts[v]));
    }
  return b;
}

// The sphere's nodes in T, from the double tree (offsets relative to the sphere).
template <typename T>
void store_nodes(SceneGeometry<T>& g, std::uint32_t s, const std::vector<BvhNode<double>>& tree, double pad) {
  for (std::size_t i = 0; i < tree.size(); ++i) {
    BvhNode<T>& n = g.nodes[g.first_node[s] + i];
    n.box = round_out<T>(tree[i].box, pad);
    n.count = tree[i].count;
    n.axis = tree[i].axis;
    n.offset = tree[i].offset + (tree[i].leaf() ? g.first[s] : g.first_node[s]);
  }
}

// Sphere s's triangles' bounds, padded like its BVH root (bvh_pad), rounded out to T.
template <typename T>
void set_local_box(SceneGeometry<T>& g, std::uint32_t s, const Mesh& mesh, const std::vector<Vec3d>& verts) {
  double magnitude = 0;
  Box<double> b;
  for (const Box<double>& t : triangle_bounds(g, mesh, verts, g.first[s], g.first[s + 1], magnitude)) b.extend(t);
  g.local_box[s] = round_out<T>(b, bvh_pad<T>(static_cast<double>(g.local_sphere[s].r), magnitude));
}

// Build sphere s's BVH and put its triangles in leaf order.
template <typename T>
void build_sphere_bvh(SceneGeometry<T>& g, std::uint32_t s, const Mesh& mesh, double radius) {
  double magnitude = 0;
  const std::uint32_t first = g.first[s], end = g.first[s + 1];
  const BvhBuild tree = build_bvh(triangle_bounds(g, mesh, mesh.vertices, first, end, magnitude));
  const std::vector<std::uint32_t> prim(g.prim.begin() + first, g.prim.begin() + end);
  for (std::uint32_t k = 0; k < tree.order.size(); ++k) {  // rewrite in leaf order, in the kernel's format
    const std::uint32_t p = prim[tree.order[k]];
    const Tri& t = mesh.triangles[p];
    g.prim[first + k] = p;
    g.tris.write(first + k, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
  }
  g.first_node[s + 1] = g.first_node[s] + static_cast<std::uint32_t>(tree.nodes.size());
  g.nodes.resize(g.first_node[s + 1]);
  store_nodes(g, s, tree.nodes, bvh_pad<T>(radius, magnitude));
}

// Refit sphere s's BVH to its triangles' current vertices.
template <typename T>
void refit_sphere_bvh(SceneGeometry<T>& g, std::uint32_t s, const Mesh& mesh, const std::vector<Vec3d>& verts) {
  std::vector<BvhNode<double>> tree(g.nodes_in(s));
  for (std::size_t i = 0; i < tree.size(); ++i) {
    const BvhNode<T>& n = g.nodes[g.first_node[s] + i];
    tree[i].count = n.count;
    tree[i].axis = n.axis;
    tree[i].offset = n.offset - (n.leaf() ? g.first[s] : g.first_node[s]);
  }
  double magnitude = 0;
  refit_bvh(tree, triangle_bounds(g, mesh, verts, g.first[s], g.first[s + 1], magnitude));
  store_nodes(g, s, tree, bvh_pad<T>(g.local_sphere[s].r, magnitude));
}
}  // namespace

Accel accel_named(const std::string& name) {
  if (name == "brute") return Accel::brute;
  if (name == "bvh") return Accel::bvh;
  throw std::invalid_argument("unknown acceleration \"" + name + "\" (expected brute or bvh)");
}

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
    set_local_box(g, s, obj.mesh, verts);
    if (g.has_bvh()) refit_sphere_bvh(g, s, obj.mesh, verts);
    bytes += g.memory_bytes(s);
  }
  return bytes;
}

template <typename T>
SceneGeometry<T> build_geometry(const Scene& scene, std::vector<SphereDef> defs, Kernel kernel, Accel accel) {
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
  if (accel == Accel::bvh) {
    g.first_node.assign(g.sphere_count() + 1, 0);
    for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
      build_sphere_bvh(g, s, scene.objects[g.object[s]].mesh, static_cast<double>(g.local_sphere[s].r));
  }
  g.local_box.resize(g.sphere_count());
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
    set_local_box(g, s, scene.objects[g.object[s]].mesh, scene.objects[g.object[s]].mesh.vertices);
  g.defs = std::move(defs);
  return g;
}

template SceneGeometry<float> build_geometry(const Scene&, std::vector<SphereDef>, Kernel, Accel);
template SceneGeometry<double> build_geometry(const Scene&, std::vector<SphereDef>, Kernel, Accel);
template std::uint64_t update_deforming(SceneGeometry<float>&, const Scene&, int);
template std::uint64_t update_deforming(SceneGeometry<double>&, const Scene&, int);

}  // namespace oprt
