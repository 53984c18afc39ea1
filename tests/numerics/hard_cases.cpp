#include "hard_cases.h"

#include "balance/spheres.h"
#include "ref/camera.h"
#include "ref/reference.h"
#include "ref/shading.h"
#include "ref/traverse.h"
#include "base/error.h"
#include "scene/generate.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <array>
#include <map>
#include <numeric>
#include <random>
#include <stdexcept>
#include <tuple>

namespace oprt::numerics {

Outcome& Outcome::operator+=(const Outcome& o) {
  trials += o.trials;
  leaks += o.leaks;
  double_hits += o.double_hits;
  sphere_misses += o.sphere_misses;
  self_hits += o.self_hits;
  wrong += o.wrong;
  return *this;
}

namespace {

using Rng = std::mt19937_64;
constexpr double kPi = 3.14159265358979323846;

double uniform(Rng& r, double a, double b) { return std::uniform_real_distribution<double>(a, b)(r); }
Vec3d random_unit(Rng& r) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3d v(n(r), n(r), n(r));
    const double l = std::sqrt(dot3(v, v));
    if (l > 1e-6) return v / l;
  }
}
Vec3d any_perpendicular(const Vec3d& n) {
  const Vec3d a = std::fabs(n.x) < 0.6 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  return glm::normalize(cross3(n, a));
}

// ---------------------------------------------------------------------------------------
// The double-precision oracle: a convex closed mesh as the intersection of its faces'
// half-spaces. It never calls a kernel.

struct Plane {
  Vec3d n;  // unit, outward
  double c;  // inside: n.x <= c
};

struct Convex {
  std::vector<Plane> planes;
  double radius = 0;  // largest |vertex|: the scale of the mesh's coordinates
};

Convex convex_of(const Mesh& m) {
  Convex cv;
  Vec3d centroid(0);
  for (const Vec3d& v : m.vertices) {
    centroid += v;
    cv.radius = std::max(cv.radius, max_abs_component(v));
  }
  centroid /= static_cast<double>(m.vertices.size());
  for (const Tri& t : m.triangles) {
    const Vec3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
    Vec3d n = cross3(b - a, c - a);
    const double l = std::sqrt(dot3(n, n));
    if (!(l > 0)) continue;
    n /= l;
    if (dot3(n, a - centroid) < 0) n = -n;
    cv.planes.push_back({n, dot3(n, a)});
  }
  return cv;
}

// > 0 inside, the distance to the nearest face plane.
double clearance(const Convex& cv, const Vec3d& x) {
  double c = kInf<double>;
  for (const Plane& p : cv.planes) c = std::min(c, p.c - dot3(p.n, x));
  return c;
}

struct Chord {
  double t_in = -kInf<double>, t_out = kInf<double>;
  bool empty() const { return !(t_out > t_in); }
};
Chord clip(const Convex& cv, const Vec3d& o, const Vec3d& d) {
  Chord ch;
  for (const Plane& p : cv.planes) {
    const double nd = dot3(p.n, d), gap = p.c - dot3(p.n, o);
    if (nd == 0) {
      if (gap < 0) return {1, 0};
    } else if (nd > 0) {
      ch.t_out = std::min(ch.t_out, gap / nd);
    } else {
      ch.t_in = std::max(ch.t_in, gap / nd);
    }
  }
  return ch;
}

// Shared edges and vertices of a mesh, found by exact coordinates (the box generator
// repeats vertices per face), with the outward normals of the triangles around them.
struct Topology {
  std::vector<Vec3d> normal;  // per triangle, unit outward
  struct Edge {
    Vec3d a, b;
    std::vector<std::uint32_t> tris;
  };
  std::vector<Edge> edges;  // shared by exactly two triangles
  struct Vertex {
    Vec3d p;
    std::vector<std::uint32_t> tris;
  };
  std::vector<Vertex> vertices;
};

Topology topology_of(const Mesh& m) {
  Topology top;
  Vec3d centroid(0);
  for (const Vec3d& v : m.vertices) centroid += v;
  centroid /= static_cast<double>(m.vertices.size());
  using Key = std::tuple<double, double, double>;
  std::map<Key, std::uint32_t> id;
  std::vector<Vec3d> points;
  auto vid = [&](const Vec3d& v) {
    auto [it, fresh] = id.emplace(Key{v.x, v.y, v.z}, static_cast<std::uint32_t>(points.size()));
    if (fresh) points.push_back(v);
    return it->second;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edges;
  std::map<std::uint32_t, std::vector<std::uint32_t>> around;
  for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
    const Tri& tri = m.triangles[t];
    const Vec3d a = m.vertices[tri[0]], b = m.vertices[tri[1]], c = m.vertices[tri[2]];
    Vec3d n = glm::normalize(cross3(b - a, c - a));
    if (dot3(n, a - centroid) < 0) n = -n;
    top.normal.push_back(n);
    std::uint32_t k[3] = {vid(a), vid(b), vid(c)};
    for (int i = 0; i < 3; ++i) {
      around[k[i]].push_back(t);
      const std::uint32_t p = k[i], q = k[(i + 1) % 3];
      edges[{std::min(p, q), std::max(p, q)}].push_back(t);
    }
  }
  for (const auto& [e, tris] : edges)
    if (tris.size() == 2) top.edges.push_back({points[e.first], points[e.second], tris});
  for (const auto& [v, tris] : around) top.vertices.push_back({points[v], tris});
  return top;
}

// A direction that enters every given face from outside at more than a grazing angle
// (n.d < -0.05 for each), randomised around their mean inward direction.
bool entering_direction(const Topology& top, const std::vector<std::uint32_t>& tris, Rng& rng, Vec3d& d) {
  Vec3d mean(0);
  for (auto t : tris) mean += top.normal[t];
  const Vec3d base = -glm::normalize(mean);
  for (int attempt = 0; attempt < 24; ++attempt) {
    const double spread = attempt < 20 ? uniform(rng, 0, 0.7) : 0;
    d = glm::normalize(base + random_unit(rng) * spread);
    bool ok = true;
    for (auto t : tris) ok = ok && dot3(top.normal[t], d) < -0.05;
    if (ok) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------
// One closed mesh placed in the world as the engine holds it: one object, one bounding
// sphere, the geometry in the kernel's format in T, the frame set-up's world sphere and
// world -> local matrix.

template <typename T>
struct Placed {
  Scene scene;
  SceneGeometry<T> g;
  FrameSetup<T> f;
  IuRegisters<T> regs;
  Convex convex;  // local, double
  double world_size = 0;

  Placed(const Mesh& mesh, const Affine<double>& to_world, Kernel k) {
    scene.source = "hard case";
    scene.materials.push_back({});
    scene.objects.push_back({"mesh", 0, mesh, std::make_shared<StaticMotion>(to_world), nullptr});
    convex = convex_of(mesh);
    world_size = max_stretch(to_world) * 2 * convex.radius;
    // The eye bounds the ray origins' magnitude (frame_setup's sphere margin relies on it):
    // put it where the test rays start, a few sizes from the object.
    Camera cam;
    cam.eye = to_world.point(Vec3d(0)) + Vec3d(4 * world_size, 0, 0);
    cam.target = to_world.point(Vec3d(0));
    scene.camera = std::make_shared<FixedCamera>(cam);
    g = build_geometry<T>(scene, make_spheres(scene, 1), k);
    f = setup_frame(scene, g, 0);
    regs.load(f, g, {0});
  }
  const Placement& placement() const { return f.placement[0]; }
  Ray<T> local(const Ray<T>& world) const { return f.to_local[0].ray(world); }

  // Every hit along the ray, testing each triangle on its own through the block function.
  std::vector<T> hits(const Ray<T>& world) const {
    const Ray<T> l = local(world);
    std::vector<T> ts;
    for (std::uint32_t k = 0; k < g.tris.size(); ++k) {
      std::uint64_t stages[kTriStages] = {}, n = 0;
      const BlockHit<T> h = nearest_in_block(g.tris, k, k + 1, l, stages, &n);
      if (h.valid()) ts.push_back(h.t);
    }
    return ts;
  }
};

// The margin by which the oracle must find a point inside (or outside) the mesh before it
// judges: the kernels see the T-rounded mesh, within a few ulps of the double one.
template <typename T>
double oracle_margin(const Convex& cv) {
  return 64 * static_cast<double>(unit_roundoff<T>()) * cv.radius;
}

// A ray from outside through a closed convex mesh, judged on the local ray the kernel
// actually sees: if the oracle finds the midpoint of its chord clearly inside and its
// origin clearly outside, the ray must hit once before the midpoint and once after.
// *t_entry: the nearest hit before the midpoint, if any.
template <typename T>
void judge_through(const Placed<T>& P, const Ray<T>& world, Outcome& out, double* t_entry = nullptr) {
  const Ray<T> l = P.local(world);
  const Vec3d o(l.o), d(l.d);
  const Chord ch = clip(P.convex, o, d);
  if (ch.empty()) return;
  const double tm = 0.5 * (ch.t_in + ch.t_out), delta = oracle_margin<T>(P.convex);
  if (!(tm > 0) || clearance(P.convex, o + d * tm) < delta || clearance(P.convex, o) > -delta) return;
  ++out.trials;
  if (!hit_sphere(world, P.f.world_sphere[0])) ++out.sphere_misses;
  int before = 0, after = 0;
  double entry = kInf<double>;
  for (T t : P.hits(world)) {
    (t < tm ? before : after) += 1;
    if (t < tm) entry = std::min(entry, static_cast<double>(t));
  }
  if (before == 0 || after == 0) ++out.leaks;
  out.double_hits += static_cast<std::uint64_t>(std::max(before - 1, 0) + std::max(after - 1, 0));
  if (t_entry) *t_entry = entry;
}

// A world ray aimed at local point q along local direction d, starting 1 to 3 object sizes
// before it. Built in double, rounded to T as the GPP rounds its rays.
template <typename T>
Ray<T> aimed(const Placed<T>& P, const Vec3d& q, const Vec3d& d_local, Rng& rng, Vec3d* o_world = nullptr,
             Vec3d* d_world = nullptr) {
  const Affine<double>& w = P.placement().to_world;
  const Vec3d qw = w.point(q), dw = glm::normalize(w.vector(d_local));
  const Vec3d ow = qw - dw * (P.world_size * uniform(rng, 1, 3));
  if (o_world) *o_world = ow;
  if (d_world) *d_world = dw;
  return {Vec3<T>(ow), Vec3<T>(dw), kInf<T>};
}

// Rays at shared edges (a random point along each, and its midpoint) and at shared
// vertices, entering every face around them.
template <typename T>
void aim_at_edges_and_vertices(const Placed<T>& P, const Topology& top, Rng& rng, int per_edge, Outcome& out,
                               bool edges = true, bool vertices = true) {
  Vec3d d;
  if (edges)
    for (const auto& e : top.edges)
      for (int i = 0; i < per_edge; ++i) {
        if (!entering_direction(top, e.tris, rng, d)) continue;
        const double s = i == 0 ? 0.5 : uniform(rng, 0.02, 0.98);
        judge_through(P, aimed(P, e.a + (e.b - e.a) * s, d, rng), out);
      }
  if (vertices)
    for (const auto& v : top.vertices)
      for (int i = 0; i < per_edge; ++i)
        if (entering_direction(top, v.tris, rng, d)) judge_through(P, aimed(P, v.p, d, rng), out);
}

// The closed meshes: a box with coplanar triangle pairs, a UV sphere (fans of thin
// triangles at its poles), a thin capped cylinder (long slivers, fans in the caps).
Vec3d centroid(const Mesh& m) {
  Vec3d c(0);
  for (const Vec3d& v : m.vertices) c += v;
  return c / static_cast<double>(m.vertices.size());
}
// A random point strictly inside a convex mesh: between its vertices' centroid and a vertex.
Vec3d inside_point(const Mesh& m, Rng& rng) {
  const Vec3d c = centroid(m);
  return c + (m.vertices[rng() % m.vertices.size()] - c) * uniform(rng, 0, 0.9);
}

const std::vector<Mesh>& closed_meshes() {
  static const std::vector<Mesh> m = {box({2, 2, 2}, 3), uv_sphere(1, 24, 12), cylinder(0.05, 2, 32, true)};
  return m;
}

Affine<double> rigid(Rng& rng, const Vec3d& offset) {
  return translate(offset) * rotate(random_unit(rng), uniform(rng, 0, 2 * kPi));
}

// ---------------------------------------------------------------------------------------
// The cases.

template <typename T>
Outcome edges_case(Kernel k) {
  Outcome out;
  Rng rng(1);
  for (const Mesh& m : closed_meshes()) {
    const Placed<T> P(m, Affine<double>::identity(), k);
    aim_at_edges_and_vertices(P, topology_of(m), rng, 4, out, true, false);
  }
  return out;
}

template <typename T>
Outcome vertices_case(Kernel k) {
  Outcome out;
  Rng rng(2);
  for (const Mesh& m : closed_meshes()) {
    const Placed<T> P(m, Affine<double>::identity(), k);
    aim_at_edges_and_vertices(P, topology_of(m), rng, 4, out, false, true);
  }
  return out;
}

template <typename T>
Outcome through_case(Kernel k) {
  Outcome out;
  Rng rng(3);
  for (const Mesh& m : closed_meshes()) {
    const Placed<T> P(m, rigid(rng, {0, 0, 0}), k);
    for (int i = 0; i < 3000; ++i) {
      const Vec3d inside = inside_point(m, rng);
      judge_through(P, aimed(P, inside, random_unit(rng), rng), out);
    }
  }
  return out;
}

// Meshes 1 to 1e5 from the origin, placed by their object transform, or (in_coordinates)
// with the placement baked into their vertices and an identity transform (as BART's
// world-space meshes come): then the kernels work with large local coordinates.
template <typename T, bool kInCoordinates = false>
Outcome far_case(Kernel k) {
  Outcome out;
  Rng rng(kInCoordinates ? 14 : 4);
  for (double offset : {1.0, 1e1, 1e2, 1e3, 1e4, 1e5})
    for (Mesh m : closed_meshes()) {
      Affine<double> to_world = rigid(rng, random_unit(rng) * offset);
      if (kInCoordinates) {
        for (Vec3d& v : m.vertices) v = to_world.point(v);
        to_world = Affine<double>::identity();
      }
      const Placed<T> P(m, to_world, k);
      aim_at_edges_and_vertices(P, topology_of(m), rng, 1, out);
    }
  return out;
}

// Scales 1e-4 to 1e4, uniform and not, placed off the origin. `wrong` counts entry hits
// whose t differs from the world distance to the entry point (computed in double from the
// world ray before rounding) by more than the rounding of the ray can explain: the local
// ray keeps the world parameter (a renormalised direction would be off by the scale).
template <typename T>
Outcome scaled_case(Kernel k) {
  Outcome out;
  Rng rng(5);
  const Vec3d scales[] = {Vec3d(1e-4), Vec3d(1e-2), Vec3d(1e2), Vec3d(1e4), {1, 1e-2, 1e2}, {1e-3, 1, 1}, {3, 3, 1e-3}};
  for (const Vec3d& s : scales)
    for (const Mesh& m : closed_meshes()) {
      const double size = std::max({s.x, s.y, s.z});
      const Affine<double> to_world = rigid(rng, random_unit(rng) * (10 * size)) * scale(s);
      const Placed<T> P(m, to_world, k);
      const Topology top = topology_of(m);
      Vec3d d;
      for (const auto& e : top.edges) {
        if (!entering_direction(top, e.tris, rng, d)) continue;
        Vec3d ow, dw;
        const Ray<T> ray = aimed(P, e.a + (e.b - e.a) * uniform(rng, 0.02, 0.98), d, rng, &ow, &dw);
        double t = kInf<double>;
        const std::uint64_t judged = out.trials;
        judge_through(P, ray, out, &t);
        if (out.trials == judged || !std::isfinite(t)) continue;
        const Affine<double>& to_local = P.placement().to_local;
        const double t_exact = clip(P.convex, to_local.point(ow), to_local.vector(dw)).t_in;
        // The ray's rounding to T, magnified by the map's condition number.
        const double cond = max_stretch(P.placement().to_world) * max_stretch(to_local);
        const double tol = 64 * static_cast<double>(unit_roundoff<T>()) * cond * (max_abs_component(ow) + t_exact);
        if (!(std::fabs(t - t_exact) <= tol)) {
          ++out.wrong;
          if (std::getenv("OPRT_DEBUG_CASES"))
            std::fprintf(stderr, "scaled (%g %g %g): t %.9g exact %.9g tol %.3g |o| %g\n", s.x, s.y, s.z, t, t_exact, tol,
                         max_abs_component(ow));
        }
      }
    }
  return out;
}

// Rays entering a face at grazing angles 1e-1 to 1e-6 rad. The oracle judges only the
// rays that pass clearly inside the T-rounded mesh, so in float the flattest are skipped.
template <typename T>
Outcome grazing_case(Kernel k) {
  Outcome out;
  Rng rng(6);
  for (const Mesh& m : closed_meshes()) {
    const Placed<T> P(m, rigid(rng, {0, 0, 0}), k);
    const Topology top = topology_of(m);
    for (int i = 0; i < 2000; ++i) {
      const std::uint32_t t = static_cast<std::uint32_t>(rng() % m.triangles.size());
      const Tri& tri = m.triangles[t];
      double a = uniform(rng, 0, 1), b = uniform(rng, 0, 1);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3d q = m.vertices[tri[0]] + (m.vertices[tri[1]] - m.vertices[tri[0]]) * a +
                      (m.vertices[tri[2]] - m.vertices[tri[0]]) * b;
      const Vec3d n = top.normal[t], tangent = glm::normalize(cross3(n, random_unit(rng)));
      const double angle = std::pow(10.0, -1 - static_cast<int>(i % 6));
      judge_through(P, aimed(P, q, tangent * std::cos(angle) - n * std::sin(angle), rng), out);
    }
  }
  return out;
}

// Directions exactly along +-x, +-y, +-z, through the grid lines of a box whose vertices
// lie on multiples of 0.5: the rays pass exactly through edges, vertices and the faces'
// diagonals, where edge functions are exactly zero. Transforms that keep every coordinate
// exact: identity, a translation, a scale by 2, an axis permutation.
template <typename T>
Outcome axis_aligned_case(Kernel k) {
  Outcome out;
  Rng rng(7);
  const Mesh m = box({2, 2, 2}, 4);
  const Affine<double> maps[] = {Affine<double>::identity(), translate({1024, -2048, 4096}), scale(Vec3d(2)),
                                 Affine<double>::from_rows({0, 0, 1, 8, 1, 0, 0, 0, 0, 1, 0, -8})};
  for (const Affine<double>& w : maps) {
    const Placed<T> P(m, w, k);
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {1.0, -1.0})
        for (int i = -7; i <= 7; ++i)
          for (int j = -7; j <= 7; ++j) {
            Vec3d o(0), d(0);
            d[axis] = sign;
            o[axis] = -3 * sign;
            o[(axis + 1) % 3] = 0.125 * i;
            o[(axis + 2) % 3] = 0.125 * j;
            const Vec3d ow = w.point(o), dw = glm::normalize(w.vector(d));
            judge_through(P, Ray<T>{Vec3<T>(ow), Vec3<T>(dw), kInf<T>}, out);
          }
  }
  return out;
}

// Ray origins inside closed meshes (so inside their bounding spheres), in every direction:
// the sphere test must accept, and the ray must leave through exactly one triangle.
template <typename T>
Outcome inside_case(Kernel k) {
  Outcome out;
  Rng rng(8);
  for (double offset : {0.0, 1e3})
    for (const Mesh& m : closed_meshes()) {
      const Placed<T> P(m, rigid(rng, random_unit(rng) * offset), k);
      const double delta = oracle_margin<T>(P.convex);
      for (int i = 0; i < 2000; ++i) {
        const Vec3d inside = inside_point(m, rng);
        const Vec3d ow = P.placement().to_world.point(inside);
        const Vec3d dw = random_unit(rng);
        const Ray<T> world{Vec3<T>(ow), Vec3<T>(dw), kInf<T>};
        const Ray<T> l = P.local(world);
        if (clearance(P.convex, Vec3d(l.o)) < delta) continue;
        ++out.trials;
        if (!hit_sphere(world, P.f.world_sphere[0])) ++out.sphere_misses;
        const auto ts = P.hits(world);
        if (ts.empty()) ++out.leaks;
        if (ts.size() > 1) out.double_hits += ts.size() - 1;
      }
    }
  return out;
}

// Bounding spheres of radius 1e-3 to 1 at 1e2 to 1e5 radii from the ray origin, hit by
// rays the oracle finds passing within 0.99 r of the centre (distance from the T-rounded
// centre to the T-rounded ray's line, in double). Counts the model's stable test; the
// textbook form's misses are the report's comparison.
template <typename T, bool kTextbook = false>
Outcome tiny_spheres(Kernel) {
  Outcome out;
  Rng rng(9);
  for (double r : {1e-3, 1e-2, 1.0})
    for (double dist : {1e2, 1e3, 1e4, 1e5})
      for (int i = 0; i < 500; ++i) {
        const Vec3d o = random_unit(rng) * uniform(rng, 0, dist);
        const Vec3d c = o + random_unit(rng) * (dist * r);
        const Vec3d aim = c + random_unit(rng) * (r * uniform(rng, 0, 1));
        const Ray<T> ray{Vec3<T>(o), Vec3<T>(glm::normalize(aim - o)), kInf<T>};
        const Sphere<T> s{Vec3<T>(c), static_cast<T>(r)};
        const Vec3d f = Vec3d(ray.o) - Vec3d(s.c), dd = glm::normalize(Vec3d(ray.d));
        const Vec3d perp = f - dd * dot3(f, dd);
        if (!(std::sqrt(dot3(perp, perp)) < 0.99 * static_cast<double>(s.r)) || dot3(f, dd) > 0) continue;
        ++out.trials;
        // The model's test as a unit's registers run it (geom/sphere_soa.h: scalar or SIMD).
        SphereSoA<T> streams;
        streams.push_back(s);
        if (!(kTextbook ? hit_sphere_textbook(ray, s) : sphere_hits({s}, streams, ray, 0, 1) == 1)) ++out.sphere_misses;
      }
  return out;
}

// Shadow rays from primary hits on closed convex meshes towards lights in the outer
// half-space, 1e-4 rad to 1.2 rad above the surface: nothing may occlude them. Origins as
// the shader makes them (offset_origin), traced through the sphere test and transform;
// kNoOffset starts them at the hit point itself, to show that the case is hard.
template <typename T, bool kNoOffset = false>
Outcome shadow_case(Kernel k) {
  Outcome out;
  Rng rng(10);
  const Affine<double> maps[] = {Affine<double>::identity(), rigid(rng, random_unit(rng) * 1e3),
                                 rigid(rng, random_unit(rng) * 1e5), rigid(rng, {1, 2, 3}) * scale(Vec3d(1e-3)),
                                 rigid(rng, {1, 2, 3}) * scale(Vec3d(1e3)), rigid(rng, {0, 0, 0}) * scale({1, 1e-2, 1e2})};
  const auto noop = [](const SphereVisit&) {};
  for (const Affine<double>& w : maps)
    for (const Mesh& m : closed_meshes()) {
      const Placed<T> P(m, w, k);
      const Topology top = topology_of(m);
      const Object& obj = P.scene.objects[0];
      for (int i = 0; i < 300; ++i) {
        const std::uint32_t t = static_cast<std::uint32_t>(rng() % m.triangles.size());
        const Tri& tri = m.triangles[t];
        const Vec3d q = (m.vertices[tri[0]] + m.vertices[tri[1]] + m.vertices[tri[2]]) / 3.0;
        const Ray<T> primary = aimed(P, q + (m.vertices[tri[rng() % 3]] - q) * uniform(rng, 0, 0.999),
                                     -top.normal[t] + random_unit(rng) * 0.5, rng);
        const HitRecord<T> hit = trace_nearest(P.g, P.regs, primary, noop);
        if (!hit.valid()) continue;
        const SurfacePoint sp = surface_point(obj, P.placement(), hit.prim, hit.u, hit.v);
        Vec3d n = sp.n;
        if (dot3(n, Vec3d(primary.d)) > 0) n = -n;
        const Vec3d tangent = any_perpendicular(n);
        for (double angle : {1e-4, 1e-3, 1e-2, 1e-1, 0.5, 1.2}) {
          const double az = uniform(rng, 0, 2 * kPi);
          const Vec3d along = tangent * std::cos(az) + cross3(n, tangent) * std::sin(az);
          const Vec3d l = glm::normalize(n * std::sin(angle) + along * std::cos(angle));
          const Vec3d origin =
              kNoOffset ? Vec3d(Vec3<T>(sp.p))
                        : offset_origin<T>(k, sp.p, n, l, P.placement(), sp.a, sp.b, sp.c, OffsetBound::isotropic);
          const Vec3d light = sp.p + l * (4 * P.world_size);
          const Vec3d d = light - origin;
          const double len = std::sqrt(dot3(d, d));
          ++out.trials;
          if (trace_any(P.g, P.regs, Ray<T>{Vec3<T>(origin), Vec3<T>(d / len), static_cast<T>(len)}, noop))
            ++out.self_hits;
        }
      }
    }
  return out;
}

// Valid maps whose columns are nearly dependent (|det| / product of column lengths from
// 1e-2 down to 1e-8, the refusal threshold being 1e-9): world spheres must still enclose,
// and whatever local line the T-rounded inverse gives, the mesh must not leak.
template <typename T>
Outcome near_singular_case(Kernel k) {
  Outcome out;
  Rng rng(11);
  for (double s : {1e-2, 1e-4, 1e-6, 1e-8})
    for (const Mesh& m : closed_meshes()) {
      // Columns x, y and cos(a) x + sin(a) z: |det| / product of lengths = sin(a) = s.
      const double c = std::sqrt(1 - s * s);
      const Affine<double> shear = Affine<double>::from_rows({1, 0, c, 0, 0, 1, 0, 0, 0, 0, s, 0});
      const Placed<T> P(m, rigid(rng, random_unit(rng) * 10.0) * shear, k);
      aim_at_edges_and_vertices(P, topology_of(m), rng, 1, out);
    }
  return out;
}

// Matrices that must be refused (NaN, infinite, singular, nearly singular beyond 1e-9)
// and one that must be accepted. `wrong` counts the set-ups that decided otherwise.
template <typename T>
Outcome invalid_transforms_case(Kernel k) {
  Outcome out;
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = kInf<double>;
  const std::pair<std::array<double, 12>, bool> maps[] = {
      {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, nan}, false},
      {{nan, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}, false},
      {{1, 0, 0, 0, 0, inf, 0, 0, 0, 0, 1, 0}, false},
      {{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, false},
      {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0}, false},        // flattened: z column zero
      {{1, 2, 3, 0, 2, 4, 6, 0, 1, 1, 1, 0}, false},        // dependent rows
      {{1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1e-12, 0}, false},    // |det| / lengths = 1e-12
      {{1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 1e-7, 0}, true},      // 1e-7: valid
      {{1e-4, 0, 0, 5, 0, 1e-4, 0, 5, 0, 0, 1e-4, 5}, true},  // tiny but well shaped
  };
  for (const auto& [rows, valid] : maps) {
    ++out.trials;
    bool accepted = true;
    try {
      const Placed<T> P(box({2, 2, 2}, 1), Affine<double>::from_rows(rows), k);
    } catch (const InputError&) {
      accepted = false;
    }
    if (accepted != valid) ++out.wrong;
  }
  return out;
}

// Zero-area triangles (collinear vertices, a repeated vertex, one point) hit by rays
// through points of their segment from every side: `wrong` counts hits, and tests that
// leave at any stage other than 'det'.
template <typename T>
Outcome degenerate_case(Kernel k) {
  Outcome out;
  Rng rng(12);
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, 0, 0}, {0.5, 0, 0}, {1, 0, 0},
                {0, 1, 0}, {0, 1, 0}, {3, 1, 0}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {9, 10, 11}, {2, 1, 0}};
  int det_stage = 0;
  while (std::string(stage_names(k)[det_stage]) != "det") ++det_stage;
  for (const Affine<double>& w : {Affine<double>::identity(), rigid(rng, {1e3, 0, 0})}) {
    const Placed<T> P(m, w, k);
    for (std::uint32_t t = 0; t < m.triangles.size(); ++t)
      for (int i = 0; i < 400; ++i) {
        const Tri& tri = m.triangles[t];
        const Vec3d a = m.vertices[tri[0]], c = m.vertices[tri[2]], b = m.vertices[tri[1]];
        const Vec3d far_end = dot3(c - a, c - a) > dot3(b - a, b - a) ? c : b;
        const Vec3d q = a + (far_end - a) * uniform(rng, 0, 1);
        const Vec3d d = i % 8 == 0 && dot3(far_end - a, far_end - a) > 0 ? glm::normalize(far_end - a)
                                                                           : random_unit(rng);
        const Ray<T> world = aimed(P, q, d, rng);
        const Ray<T> l = P.local(world);
        ++out.trials;
        std::uint64_t stages[kTriStages] = {}, hits = 0;
        nearest_in_block(P.g.tris, t, t + 1, l, stages, &hits);
        if (hits || stages[det_stage] != 1) ++out.wrong;
      }
  }
  return out;
}


}  // namespace

const std::vector<HardCase>& hard_cases() {
  static const std::vector<HardCase> cases = {
      {"shared edges", "rays at points of edges shared by two triangles of closed meshes", true,
       edges_case<float>, edges_case<double>},
      {"shared vertices", "rays at vertices shared by 3 to 24 triangles of closed meshes", true,
       vertices_case<float>, vertices_case<double>},
      {"through", "random rays through closed meshes: each must enter and leave", true, through_case<float>,
       through_case<double>},
      {"far from origin", "edges and vertices of meshes placed 1 to 1e5 from the origin", true, far_case<float>,
       far_case<double>},
      {"far in coordinates", "the same with the placement in the vertices (identity transform)", true,
       far_case<float, true>, far_case<double, true>},
      {"scaled", "edges of meshes scaled 1e-4 to 1e4, also non-uniformly; wrong: t is not the world distance", true,
       scaled_case<float>, scaled_case<double>},
      {"grazing", "rays entering a face at 1e-1 to 1e-6 rad", false, grazing_case<float>, grazing_case<double>},
      {"axis-aligned", "directions exactly +-x, +-y, +-z through a box's edges, vertices and diagonals", true,
       axis_aligned_case<float>, axis_aligned_case<double>},
      {"camera inside", "origins inside closed meshes and their spheres: exactly one exit each", true,
       inside_case<float>, inside_case<double>},
      {"tiny spheres far away", "spheres of radius 1e-3 to 1 at 1e2 to 1e5 radii, rays through 0.99 r", true,
       tiny_spheres<float>, tiny_spheres<double>},
      {"shadow rays", "shadow rays leaving convex meshes at 1e-4 to 1.2 rad, under six transforms", true,
       shadow_case<float>, shadow_case<double>},
      {"near-singular transforms", "|det| / column lengths 1e-2 to 1e-8: spheres enclose, no leaks", true,
       near_singular_case<float>, near_singular_case<double>},
      {"invalid transforms", "NaN, infinite, singular maps refused; wrong: a set-up that decided otherwise", true,
       invalid_transforms_case<float>, invalid_transforms_case<double>},
      {"degenerate triangles", "zero-area triangles; wrong: a hit, or an exit before/after 'det'", true,
       degenerate_case<float>, degenerate_case<double>},
  };
  return cases;
}

const HardCase& hard_case(const std::string& name) {
  for (const HardCase& c : hard_cases())
    if (c.name == name) return c;
  throw std::out_of_range("no hard case named \"" + name + "\"");
}

Outcome textbook_sphere_case(bool dbl) {
  return dbl ? tiny_spheres<double, true>(Kernel::moller) : tiny_spheres<float, true>(Kernel::moller);
}

namespace {
// One closed convex mesh 1e5 from the origin seen through a long lens from 40 radii away
// (a long ray to the mesh widens the band around an edge where a non-watertight test can
// lose a pixel), one light.
Scene far_scene(const Mesh& mesh, const Affine<double>& to_world, int size) {
  Scene s;
  s.source = "image check";
  s.width = s.height = size;
  s.materials.push_back({});
  s.objects.push_back({"mesh", 0, mesh, std::make_shared<StaticMotion>(to_world), nullptr});
  const Vec3d c0 = centroid(mesh);
  double r = 0;
  for (const Vec3d& v : mesh.vertices) r = std::max(r, std::sqrt(dot3(v - c0, v - c0)));
  r *= max_stretch(to_world);
  const Vec3d c = to_world.point(c0);
  Camera cam;
  cam.eye = c + glm::normalize(Vec3d(0.3, 0.4, 1)) * (40 * r);
  cam.target = c;
  cam.fov_y_deg = 3.5;
  s.camera = std::make_shared<FixedCamera>(cam);
  s.lights.push_back({cam.eye + Vec3d(r, 2 * r, 0), Vec3d(1), nullptr});
  return s;
}

template <typename T>
ImageCheck image_check_t(Kernel k, bool in_coordinates, int size) {
  ImageCheck out;
  Rng rng(13);
  const Vec3d offset = Vec3d(1, 0.3, -0.2) * 1e5;
  const std::pair<Mesh, double> meshes[] = {{uv_sphere(1, 48, 24), 50.0}, {box({2, 2, 2}, 8), 40.0}};
  for (auto [mesh, scale_by] : meshes) {
    Affine<double> to_world = rigid(rng, offset) * scale(Vec3d(scale_by));
    if (in_coordinates) {  // the placement baked into the vertices; the object's map is identity
      for (Vec3d& v : mesh.vertices) v = to_world.point(v);
      to_world = Affine<double>::identity();
      scale_by = 1;
    }
    const Scene scene = far_scene(mesh, to_world, size);
    const SceneGeometry<T> g = build_geometry<T>(scene, make_spheres(scene, 1), k);
    const FrameResult r = render_reference(scene, g, 0, size, size);
    // The oracle: the double camera ray, in the local frame, passes clearly inside the
    // mesh (by more than float's rounding of rays 1e5 from the origin can move it).
    const Convex cv = convex_of(mesh);
    const Placement pl = *make_placement(scene.objects[0].motion->at(0));
    const double margin = 64 * static_cast<double>(unit_roundoff<float>()) * 2 * max_abs_component(offset) / scale_by;
    const CameraRays cam(scene.camera->at(0), size, size);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const Ray<double> w = cam.ray<double>(x, y);
        const Vec3d o = pl.to_local.point(w.o), d = pl.to_local.vector(w.d);
        const Chord ch = clip(cv, o, d);
        const double tm = 0.5 * (ch.t_in + ch.t_out);
        if (ch.empty() || clearance(cv, o + d * tm) < margin) continue;
        ++out.inside_pixels;
        const std::size_t i = static_cast<std::size_t>(y) * size + x;
        if (r.image.object[i] == kNone) ++out.background_inside;
        else if (r.image.z[i] > tm) ++out.see_through;  // the front was missed, the back shows
      }
  }
  return out;
}
}  // namespace

ImageCheck image_check(Kernel k, bool dbl, bool in_coordinates, int size) {
  return dbl ? image_check_t<double>(k, in_coordinates, size) : image_check_t<float>(k, in_coordinates, size);
}

Outcome shadow_case_without_offset(Kernel k, bool dbl) {
  return dbl ? shadow_case<double, true>(k) : shadow_case<float, true>(k);
}

// ---------------------------------------------------------------------------------------
// Issue 29: Whitted ray trees on hard geometry (hard_cases.h says what is judged).

TreeOutcome& TreeOutcome::operator+=(const TreeOutcome& o) {
  primaries += o.primaries;
  reflection += o.reflection;
  refraction += o.refraction;
  deepest += o.deepest;
  tir += o.tir;
  self_hits += o.self_hits;
  surface_hits += o.surface_hits;
  leaks += o.leaks;
  overshoots += o.overshoots;
  crossings += o.crossings;
  self_t_max = std::max(self_t_max, o.self_t_max);
  return *this;
}

namespace {

// What exact geometry says about a ray leaving an object's surface: a closed convex mesh
// is never met again by a ray leaving it outward, and is left exactly once by a ray going
// in; a planar mesh is never met again at all.
enum class Shape { convex, planar };

struct Part {
  Mesh mesh;
  Affine<double> to_world;
  Shape shape;
};

// Several meshes of one material placed in the world as the engine holds them, one sphere
// each, every sphere in one register file; one light; depth kSecondaryDepth.
template <typename T>
struct TreeScene {
  Scene scene;
  SceneGeometry<T> g;
  FrameSetup<T> f;
  IuRegisters<T> regs;
  std::vector<Shape> shape;                  // per object
  std::vector<Convex> convex;                // per object, local, double
  std::vector<std::vector<Vec3d>> outward;   // per object and triangle, local, unit (convex only)
  Vec3d centre{0};
  double world_size = 0;

  TreeScene(const std::vector<Part>& parts, const Material& material, Kernel k) {
    scene.source = "secondary hard case";
    scene.materials.push_back(material);
    scene.depth = kSecondaryDepth;
    Vec3d lo(kInf<double>), hi(-kInf<double>);
    for (const Part& p : parts) {
      scene.objects.push_back({"part", 0, p.mesh, std::make_shared<StaticMotion>(p.to_world), nullptr});
      shape.push_back(p.shape);
      convex.push_back(convex_of(p.mesh));
      outward.push_back(p.shape == Shape::convex ? topology_of(p.mesh).normal : std::vector<Vec3d>{});
      for (const Vec3d& v : p.mesh.vertices) {
        const Vec3d w = p.to_world.point(v);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
    }
    centre = (lo + hi) * 0.5;
    world_size = max_abs_component(hi - lo);
    // The eye bounds the ray origins' magnitude (frame_setup's sphere margin relies on it):
    // the primary rays start within 3 sizes of the centre.
    Camera cam;
    cam.eye = centre + Vec3d(4 * world_size, 0, 0);
    cam.target = centre;
    scene.camera = std::make_shared<FixedCamera>(cam);
    scene.lights.push_back({centre + Vec3d(1, 3, 2) * world_size, Vec3d(1), nullptr});
    g = build_geometry<T>(scene, make_spheres(scene, 1), k);
    f = setup_frame(scene, g, 0);
    std::vector<std::uint32_t> all(g.sphere_count());
    std::iota(all.begin(), all.end(), 0u);
    regs.load(f, g, all);
  }
};

template <typename T>
struct TreeRay {
  SpawnedRay<T> spawned;
  int depth = 0;
  std::uint32_t object = kNone, prim = kNone;  // the hit that spawned it
};

// Judge one reflection or refraction ray by its nearest hit (hard_cases.h).
template <typename T>
void judge_secondary(const TreeScene<T>& S, const TreeRay<T>& r, const HitRecord<T>& h, TreeOutcome& out) {
  const bool on_parent = h.valid() && h.object == r.object;
  auto self = [&](std::uint64_t& count) {
    ++count;
    if (std::getenv("OPRT_DEBUG_CASES"))
      std::fprintf(stderr, "%s %s depth %d: object %u prim %u -> prim %u t %.9g, origin (%.9g %.9g %.9g) dir (%.6g %.6g %.6g)\n",
                   &count == &out.self_hits ? "self" : "surface",
                   r.spawned.kind == RayKind::reflection ? "reflection" : "refraction", r.depth, r.object, r.prim,
                   h.prim, static_cast<double>(h.t), static_cast<double>(r.spawned.ray.o.x),
                   static_cast<double>(r.spawned.ray.o.y), static_cast<double>(r.spawned.ray.o.z),
                   static_cast<double>(r.spawned.ray.d.x), static_cast<double>(r.spawned.ray.d.y),
                   static_cast<double>(r.spawned.ray.d.z));
    out.self_t_max = std::max(out.self_t_max, static_cast<double>(h.t));
  };
  if (on_parent && h.prim == r.prim) return self(out.self_hits);
  if (S.shape[r.object] == Shape::planar) {
    if (on_parent) self(out.surface_hits);
    return;
  }
  const Ray<T> l = S.f.to_local[r.object].ray(r.spawned.ray);
  const Vec3d o(l.o), d(l.d);
  if (dot3(S.outward[r.object][r.prim], d) > 0) {  // leaving the convex mesh
    if (on_parent) self(out.surface_hits);
    return;
  }
  // Going in (or staying inside). Where does the ray start? Its world origin (T) mapped to
  // local in double: outside the mesh by more than the origin's own rounding to T can place
  // it (a few ulps of its coordinates, in local units) means the offset pushed it through to
  // the far side (an overshoot: the ray then skips the surface it should leave by); within
  // that rounding, nothing is judged. Inside, but its T-rounded local origin (what the
  // kernel sees) outside: the world -> local rounding carried it across another face near
  // an edge (a crossing). Else the oracle's exit, judged where it lies clearly beyond
  // rounding.
  const Convex& cv = S.convex[r.object];
  const Placement& pl = S.f.placement[r.object];
  const Vec3d ow(r.spawned.ray.o);
  const double exact = clearance(cv, pl.to_local.point(ow));
  const double resolution =
      4 * static_cast<double>(unit_roundoff<T>()) * max_abs_component(ow) * max_stretch(pl.to_local) + oracle_margin<T>(cv);
  if (exact < -resolution) {
    ++out.overshoots;
    return;
  }
  if (exact < resolution) return;
  if (clearance(cv, o) < 0) {
    ++out.crossings;
    return;
  }
  const Chord ch = clip(cv, o, d);
  const double len = std::sqrt(dot3(d, d));
  if (ch.empty() || !(ch.t_out * len > 4 * oracle_margin<T>(cv))) return;
  if (!h.valid()) ++out.leaks;
  else if (on_parent && h.t < 0.5 * ch.t_out) self(out.surface_hits);
}

// A primary ray's tree, to the depth bound, as the GPP traces it (every reflection and
// refraction ray judged; shadow rays left to the "shadow rays" case). kNoOffset starts each
// secondary ray at its hit point itself, rounded to T.
template <typename T, bool kNoOffset>
void trace_tree(const TreeScene<T>& S, const Shader<T>& shader, const Ray<T>& primary, TreeOutcome& out) {
  const auto noop = [](const SphereVisit&) {};
  const HitRecord<T> first = trace_nearest(S.g, S.regs, primary, noop);
  if (!first.valid()) return;
  ++out.primaries;
  std::vector<TreeRay<T>> todo;
  std::vector<SpawnedRay<T>> spawned;
  const Material& mat = S.scene.materials[0];
  auto expand = [&](const Ray<T>& ray, const HitRecord<T>& h, int depth, bool inside) {
    spawned.clear();
    shader.shade(ray, h, depth, inside, spawned);
    const SurfacePoint sp = surface_point(S.scene.objects[h.object], S.f.placement[h.object], h.prim, h.u, h.v);
    if (depth < kSecondaryDepth && mat.transmits()) {  // Snell's k < 0, as the shader decides it
      const Vec3d d = glm::normalize(Vec3d(ray.d));
      const Vec3d nf = dot3(sp.n, d) > 0 ? -sp.n : sp.n;
      const Vec3d ns = dot3(sp.shading, nf) < 0 ? -sp.shading : sp.shading;
      const double eta = inside ? mat.ior : 1 / mat.ior, cos_i = -dot3(d, ns);
      if (1 - eta * eta * (1 - cos_i * cos_i) < 0) ++out.tir;
    }
    for (const SpawnedRay<T>& s : spawned) {
      if (s.kind == RayKind::shadow) continue;
      TreeRay<T> r{s, depth + 1, h.object, h.prim};
      if (kNoOffset) r.spawned.ray.o = Vec3<T>(sp.p);
      todo.push_back(r);
    }
  };
  expand(primary, first, 0, false);
  while (!todo.empty()) {
    const TreeRay<T> r = todo.back();
    todo.pop_back();
    ++(r.spawned.kind == RayKind::reflection ? out.reflection : out.refraction);
    if (r.depth == kSecondaryDepth) ++out.deepest;
    const HitRecord<T> h = trace_nearest(S.g, S.regs, r.spawned.ray, noop);
    judge_secondary(S, r, h, out);
    if (h.valid()) expand(r.spawned.ray, h, r.depth, r.spawned.inside);
  }
}

// The shadow case's six maps: identity, far from the origin (1e3, 1e5), scaled by 1e-3 and
// 1e3, and scaled non-uniformly (1, 1e-2, 1e2).
std::vector<Affine<double>> six_maps(Rng& rng) {
  std::vector<Affine<double>> maps = {Affine<double>::identity()};
  maps.push_back(rigid(rng, random_unit(rng) * 1e3));
  maps.push_back(rigid(rng, random_unit(rng) * 1e5));
  maps.push_back(rigid(rng, {1, 2, 3}) * scale(Vec3d(1e-3)));
  maps.push_back(rigid(rng, {1, 2, 3}) * scale(Vec3d(1e3)));
  maps.push_back(rigid(rng, {0, 0, 0}) * scale({1, 1e-2, 1e2}));
  return maps;
}

// A UV sphere with its vertex normals published (its shading normals interpolated).
Mesh smooth_sphere(std::uint32_t segments, std::uint32_t rings) {
  Mesh m = uv_sphere(1, segments, rings);
  for (const Vec3d& v : m.vertices) m.normals.push_back(glm::normalize(v));
  m.normal_index = m.triangles;
  return m;
}

// A glass sphere seen through: transmit 1, ior 1.5; a coarse faceted sphere (its flat
// facets turn rays inside past the critical angle: total internal reflection) and a fine
// one shaded smooth by its published normals. Rays from a viewpoint 3 sizes away towards
// random points of the disc it covers (out to its silhouette), under the six maps.
template <typename T, bool kNoOffset = false>
TreeOutcome glass_sphere_case(Kernel k) {
  TreeOutcome out;
  Rng rng(21);
  Material glass;
  glass.diffuse = Vec3d(0.05);
  glass.transmit = Vec3d(1);
  glass.ior = 1.5;
  for (const Affine<double>& w : six_maps(rng))
    for (const Mesh& m : {uv_sphere(1, 12, 6), smooth_sphere(48, 24)}) {
      const TreeScene<T> S({{m, w, Shape::convex}}, glass, k);
      const Shader<T> shader(S.scene, S.f, kSecondaryDepth);
      for (int i = 0; i < 400; ++i) {
        const Vec3d view = random_unit(rng), side = any_perpendicular(view), up = cross3(view, side);
        const double r = 1.02 * std::sqrt(uniform(rng, 0, 1)), a = uniform(rng, 0, 2 * kPi);
        const Vec3d target = w.point(side * (r * std::cos(a)) + up * (r * std::sin(a)));
        const Vec3d eye = w.point(Vec3d(0)) - glm::normalize(w.vector(view)) * (3 * S.world_size);
        const Vec3d d = glm::normalize(target - eye);
        trace_tree<T, kNoOffset>(S, shader, Ray<T>{Vec3<T>(eye), Vec3<T>(d), kInf<T>}, out);
      }
    }
  return out;
}

// Two mirrors facing each other (reflect 1), 40 x 40 grids of 8 x 8 quads a distance 1
// apart: rays start between them at 0.2 to pi/2 rad from the mirrors' plane (exactly
// perpendicular ones retrace their path) and bounce back and forth to the depth bound;
// under the six maps.
template <typename T, bool kNoOffset = false>
TreeOutcome mirrors_case(Kernel k) {
  TreeOutcome out;
  Rng rng(22);
  Material mirror;
  mirror.diffuse = Vec3d(0.05);
  mirror.reflect = Vec3d(1);
  const Mesh sheet = plane(40, 40, 8, 8);  // in y = 0, facing +y
  const Affine<double> upper = translate({0, 1, 0}) * rotate({1, 0, 0}, kPi);  // in y = 1, facing -y
  for (const Affine<double>& w : six_maps(rng)) {
    const TreeScene<T> S({{sheet, w, Shape::planar}, {sheet, w * upper, Shape::planar}}, mirror, k);
    const Shader<T> shader(S.scene, S.f, kSecondaryDepth);
    for (int i = 0; i < 300; ++i) {
      const double elevation = i % 10 == 0 ? kPi / 2 : uniform(rng, 0.2, kPi / 2), az = uniform(rng, 0, 2 * kPi);
      const Vec3d o(uniform(rng, -3, 3), uniform(rng, 0.2, 0.8), uniform(rng, -3, 3));
      const Vec3d d(std::cos(elevation) * std::cos(az), (i % 2 ? 1 : -1) * std::sin(elevation),
                    std::cos(elevation) * std::sin(az));
      const Vec3d ow = w.point(o), dw = glm::normalize(w.vector(d));
      trace_tree<T, kNoOffset>(S, shader, Ray<T>{Vec3<T>(ow), Vec3<T>(dw), kInf<T>}, out);
    }
  }
  return out;
}

// The closed meshes of the cases above (a subdivided box, a UV sphere, a thin capped
// cylinder of slivers) made half mirror, half glass (reflect 0.5, transmit 0.5, ior 1.5):
// every hit spawns a reflection and (but for total internal reflection) a refraction ray.
// Primary rays as the shadow case aims them, under its six maps.
template <typename T, bool kNoOffset = false>
TreeOutcome closed_meshes_case(Kernel k) {
  TreeOutcome out;
  Rng rng(23);
  Material half;
  half.diffuse = Vec3d(0.05);
  half.reflect = Vec3d(0.5);
  half.transmit = Vec3d(0.5);
  half.ior = 1.5;
  for (const Affine<double>& w : six_maps(rng))
    for (const Mesh& m : closed_meshes()) {
      const TreeScene<T> S({{m, w, Shape::convex}}, half, k);
      const Shader<T> shader(S.scene, S.f, kSecondaryDepth);
      const std::vector<Vec3d>& normal = S.outward[0];
      for (int i = 0; i < 200; ++i) {
        const std::uint32_t t = static_cast<std::uint32_t>(rng() % m.triangles.size());
        const Tri& tri = m.triangles[t];
        const Vec3d q = (m.vertices[tri[0]] + m.vertices[tri[1]] + m.vertices[tri[2]]) / 3.0;
        const Vec3d aim = q + (m.vertices[tri[rng() % 3]] - q) * uniform(rng, 0, 0.999);
        const Vec3d dl = glm::normalize(-normal[t] + random_unit(rng) * 0.5);
        const Vec3d dw = glm::normalize(w.vector(dl)), ow = w.point(aim) - dw * (S.world_size * uniform(rng, 1, 3));
        trace_tree<T, kNoOffset>(S, shader, Ray<T>{Vec3<T>(ow), Vec3<T>(dw), kInf<T>}, out);
      }
    }
  return out;
}

}  // namespace

const std::vector<SecondaryCase>& secondary_cases() {
  static const std::vector<SecondaryCase> cases = {
      {"glass sphere", "a faceted and a smooth-shaded sphere, transmit 1, ior 1.5, seen through under six maps",
       glass_sphere_case<float>, glass_sphere_case<double>},
      {"facing mirrors", "two mirrors 1 apart, rays bouncing between them to the depth bound, under six maps",
       mirrors_case<float>, mirrors_case<double>},
      {"closed meshes, reflect and transmit", "box, sphere, thin cylinder, reflect 0.5, transmit 0.5, ior 1.5",
       closed_meshes_case<float>, closed_meshes_case<double>},
  };
  return cases;
}

const SecondaryCase& secondary_case(const std::string& name) {
  for (const SecondaryCase& c : secondary_cases())
    if (c.name == name) return c;
  throw std::out_of_range("no secondary case named \"" + name + "\"");
}

TreeOutcome secondary_case_without_offset(const std::string& name, Kernel k, bool dbl) {
  if (name == "glass sphere") return dbl ? glass_sphere_case<double, true>(k) : glass_sphere_case<float, true>(k);
  if (name == "facing mirrors") return dbl ? mirrors_case<double, true>(k) : mirrors_case<float, true>(k);
  if (name == "closed meshes, reflect and transmit")
    return dbl ? closed_meshes_case<double, true>(k) : closed_meshes_case<float, true>(k);
  throw std::out_of_range("no secondary case named \"" + name + "\"");
}

}  // namespace oprt::numerics
