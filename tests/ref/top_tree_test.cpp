// --top bvh: a unit's tree over its spheres gives each unit exactly the answer of its flat
// list (nearest hit t, object, prim, u, v bit for bit; occlusion), on the paper's room split
// into 8 and on triangle soups in rotated, scaled frames with rays aimed at vertices, edges
// and planes; the tree is built once and refitted to later frames.
#include "balance/policy.h"
#include "ref/frame_trace.h"
#include "ref/reference.h"
#include "scene/load.h"
#include "test_scenes.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

namespace {

template <typename T>
bool same(const HitRecord<T>& a, const HitRecord<T>& b) {
  return a.t == b.t && a.object == b.object && a.prim == b.prim && a.u == b.u && a.v == b.v;
}

// Units as a policy would fill them: sphere i on unit i mod n.
std::vector<std::vector<std::uint32_t>> round_robin(std::uint32_t spheres, std::uint32_t units) {
  std::vector<std::vector<std::uint32_t>> a(units);
  for (std::uint32_t s = 0; s < spheres; ++s) a[s % units].push_back(s);
  return a;
}

// Per unit its flat registers and the same with its tree, for frame f.
template <typename T>
struct Units {
  std::vector<IuRegisters<T>> flat, tree;
  std::vector<TopTree> trees;
  std::uint64_t built = 0;
  void load(const FrameSetup<T>& f, const SceneGeometry<T>& g, const std::vector<std::vector<std::uint32_t>>& a) {
    flat.resize(a.size());
    tree.resize(a.size());
    trees.resize(a.size());
    for (std::size_t u = 0; u < a.size(); ++u) {
      flat[u].load(f, g, a[u]);
      tree[u].load(f, g, a[u]);
      load_top(tree[u], trees[u], a[u], f, g, &built);
    }
  }
};

// Work of a walk: node tests and sphere tests, over its visits.
struct Tally {
  std::uint64_t nodes = 0, spheres = 0, entered = 0;
  void operator()(const SphereVisit& v) {
    nodes += v.nodes_before;
    if (v.sphere == kNone) return;
    spheres += v.work.sphere_tests;
    entered += v.work.transforms;
  }
};

// Every unit's answer to ray r, flat against tree; returns whether any unit hit (nearest).
template <typename T>
bool check_ray(const SceneGeometry<T>& g, const Units<T>& units, const Ray<T>& ray, Tally& flat, Tally& tree) {
  bool any = false;
  for (std::size_t u = 0; u < units.flat.size(); ++u) {
    const HitRecord<T> a = trace_nearest(g, units.flat[u], ray, flat);
    const HitRecord<T> b = trace_nearest(g, units.tree[u], ray, tree);
    INFO("unit " << u);
    REQUIRE(same(a, b));
    any = any || a.valid();
  }
  return any;
}

template <typename T>
bool check_shadow(const SceneGeometry<T>& g, const Units<T>& units, const Ray<T>& ray, Tally& flat, Tally& tree) {
  bool any = false;
  for (std::size_t u = 0; u < units.flat.size(); ++u) {
    const bool a = trace_any(g, units.flat[u], ray, flat), b = trace_any(g, units.tree[u], ray, tree);
    INFO("unit " << u);
    REQUIRE(a == b);
    any = any || a;
  }
  return any;
}

template <typename T>
void check_paper_room(Accel accel) {
  const Scene s = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  const auto spheres = make_spheres(s, 8);
  const SceneGeometry<T> g = build_geometry<T>(s, spheres, Kernel::moller, accel);
  const auto a = static_assignment("sa_n", s, spheres, 32).unit;
  Units<T> units;
  Tally flat, tree;
  std::uint64_t hits = 0, occluded = 0;
  for (int frame : {0, 17}) {  // built at frame 0, refitted to frame 17
    const FrameSetup<T> f = setup_frame(s, g, frame);
    units.load(f, g, a);
    const CameraRays cam(f.camera, 48, 48);
    const Shader<T> shader(s, f);
    std::vector<SpawnedRay<T>> shadow;  // the scene spawns shadow rays only
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 48; ++x) {
        const Ray<T> ray = cam.ray<T>(x, y);
        if (!check_ray(g, units, ray, flat, tree)) continue;
        ++hits;
        HitRecord<T> best;  // the GPP's merge
        for (const IuRegisters<T>& r : units.flat) {
          const HitRecord<T> h = trace_nearest(g, r, ray, [](const SphereVisit&) {});
          if (h.valid() && closer(h, best)) best = h;
        }
        shadow.clear();
        shader.shade(ray, best, 0, false, shadow);
        for (const SpawnedRay<T>& sr : shadow) occluded += check_shadow(g, units, sr.ray, flat, tree);
      }
  }
  // Built once for every unit (a tree over n spheres has 2n - 1 nodes), never rebuilt.
  CHECK(units.built == 2 * spheres.size() - 32);
  CHECK(hits > 2 * 48 * 48 * 3 / 4);
  CHECK(occluded > 500);
  // The tree enters fewer spheres (it skips those beyond the nearest hit and the light) and
  // tests far fewer of them; it adds node tests.
  CHECK(tree.entered < flat.entered);
  CHECK(tree.spheres * 10 < flat.spheres);
  CHECK(tree.nodes > 0);
  CHECK(flat.nodes == 0);
}

Object moved(Mesh m, const std::string& name, const Affine<double>& to_world) {
  return Object{name, 0, std::move(m), std::make_shared<StaticMotion>(to_world), nullptr};
}

// Random triangles, a fan grid (shared edges and vertices), stacked right triangles hit at
// bit-identical t (power-of-two legs), each object in its own rotated and scaled frame.
Scene soup(std::mt19937_64& rng) {
  Scene s = test::shadow_box(8);
  s.objects.clear();
  std::uniform_real_distribution<double> pos(-8, 8), size(0.05, 3);
  Mesh random;
  for (int i = 0; i < 300; ++i) {
    const Vec3d c(pos(rng), pos(rng), pos(rng));
    const auto b = static_cast<std::uint32_t>(random.vertices.size());
    random.vertices.insert(random.vertices.end(), {c, c + Vec3d(size(rng), pos(rng) / 8, 0), c + Vec3d(0, size(rng), size(rng))});
    random.triangles.push_back({b, b + 1, b + 2});
  }
  Mesh grid;
  for (int j = 0; j <= 12; ++j)
    for (int i = 0; i <= 12; ++i) grid.vertices.push_back({-6.0 + i, -6.0 + j, 0});
  for (std::uint32_t j = 0; j < 12; ++j)
    for (std::uint32_t i = 0; i < 12; ++i) {
      const std::uint32_t v = j * 13 + i;
      grid.triangles.push_back({v, v + 1, v + 14});
      grid.triangles.push_back({v, v + 14, v + 13});
    }
  Mesh stack;
  std::uniform_int_distribution<int> cell(-6, 5), leg(0, 2);
  for (int i = 0; i < 200; ++i) {
    const double x = cell(rng), y = cell(rng), l = std::ldexp(1.0, leg(rng));
    const auto b = static_cast<std::uint32_t>(stack.vertices.size());
    stack.vertices.insert(stack.vertices.end(), {{x, y, 2}, {x + l, y, 2}, {x, y + l, 2}});
    stack.triangles.push_back({b, b + 1, b + 2});
  }
  // Rotations about skew axes, a uniform scale, a translation: world boxes of rotated
  // local boxes, and rounding in every transform.
  auto frame = [](double deg, Vec3d axis, double scale, Vec3d t) {
    const double c = std::cos(deg * 3.14159265358979 / 180), sn = std::sin(deg * 3.14159265358979 / 180);
    axis = axis / std::sqrt(dot3(axis, axis));
    const double x = axis.x, y = axis.y, z = axis.z;
    const double r[3][3] = {{c + x * x * (1 - c), x * y * (1 - c) - z * sn, x * z * (1 - c) + y * sn},
                            {y * x * (1 - c) + z * sn, c + y * y * (1 - c), y * z * (1 - c) - x * sn},
                            {z * x * (1 - c) - y * sn, z * y * (1 - c) + x * sn, c + z * z * (1 - c)}};
    std::array<double, 12> m{};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[4 * i + j] = scale * r[i][j];
      m[4 * i + 3] = t[i];
    }
    return Affine<double>::from_rows(m);
  };
  s.objects = {moved(random, "random", frame(37, {1, 2, 3}, 0.7, {1, -2, 0.5})),
               moved(grid, "grid", Affine<double>::identity()),
               moved(stack, "stack", frame(90, {0, 0, 1}, 1, {0.25, 0, 0}))};
  return s;
}

template <typename T>
void check_soup(Kernel kernel, Accel accel) {
  std::mt19937_64 rng(77);
  const Scene s = soup(rng);
  const auto spheres = make_spheres(s, 6);
  const SceneGeometry<T> g = build_geometry<T>(s, spheres, kernel, accel);
  const FrameSetup<T> f = setup_frame(s, g, 0);
  Units<T> units;
  units.load(f, g, round_robin(g.sphere_count(), 3));
  std::uniform_real_distribution<double> pos(-14, 14), unit(0, 1), len(0.1, 30);
  int through_vertex = 0, through_edge = 0, in_plane = 0, hits = 0, occluded = 0;
  Tally flat, tree;
  for (int i = 0; i < 20000; ++i) {
    const Object& obj = s.objects[i % s.objects.size()];
    const Affine<double>& m = f.placement[i % s.objects.size()].to_world;
    const Tri& tri = obj.mesh.triangles[(i / 4) % obj.mesh.triangles.size()];
    const Vec3d a = m.point(obj.mesh.vertices[tri[0]]), b = m.point(obj.mesh.vertices[tri[1]]),
                c = m.point(obj.mesh.vertices[tri[2]]);
    Vec3d target;
    const int kind = i % 5;
    if (kind == 0) target = a, ++through_vertex;
    else if (kind == 1) target = (a + b) * 0.5, ++through_edge;
    else target = a + (b - a) * unit(rng) * 0.5 + (c - a) * unit(rng) * 0.5;
    Vec3d o(pos(rng), pos(rng), pos(rng));
    if (kind == 4 && obj.name == "grid") {  // in the plane of the grid's triangles
      o.z = a.z;
      ++in_plane;
    }
    Vec3d d = target - o;
    if (dot3(d, d) == 0) continue;
    d = d / std::sqrt(dot3(d, d));
    INFO("ray " << i << " kind " << kind);
    hits += check_ray(g, units, Ray<T>{Vec3<T>(o), Vec3<T>(d), kInf<T>}, flat, tree);
    occluded += check_shadow(g, units, Ray<T>{Vec3<T>(o), Vec3<T>(d), static_cast<T>(len(rng))}, flat, tree);
  }
  INFO("hits " << hits << ", through vertices " << through_vertex << ", through edges " << through_edge
               << ", in a triangle's plane " << in_plane << ", occluded " << occluded);
  CHECK(hits > 10000);
  CHECK(in_plane > 1000);
  CHECK(occluded > 3000);
  CHECK(tree.entered < flat.entered);
}

}  // namespace

TEMPLATE_TEST_CASE("top: every unit's answers with a tree equal its flat list's on paper_room split into 8",
                   "[top][reference]", float, double) {
  check_paper_room<TestType>(Accel::brute);
}

TEST_CASE("top: with a BVH in each sphere too, every unit's answers equal its flat list's", "[top][reference][bvh]") {
  check_paper_room<float>(Accel::bvh);
}

TEMPLATE_TEST_CASE("top: on triangle soups in rotated frames with hard rays, answers equal the flat list's",
                   "[top][hard]", float, double) {
  check_soup<TestType>(Kernel::moller, Accel::brute);
  check_soup<TestType>(Kernel::moller, Accel::bvh);
}

TEMPLATE_TEST_CASE("top: the watertight kernel's answers with a tree equal its flat list's", "[top][hard][watertight]",
                   float, double) {
  check_soup<TestType>(Kernel::watertight, Accel::brute);
}

TEST_CASE("top: every point of a sphere's triangles lies in its world bounds", "[top]") {
  std::mt19937_64 rng(3);
  const Scene s = soup(rng);
  const auto spheres = make_spheres(s, 6);
  const SceneGeometry<float> g = build_geometry<float>(s, spheres, Accel::brute);
  const FrameSetup<float> f = setup_frame(s, g, 0);
  std::uniform_real_distribution<double> unit(0, 1);
  int points = 0;
  for (std::uint32_t k = 0; k < g.sphere_count(); ++k) {
    const Box<double> b = world_bounds(f, g, k);
    const Affine<double>& m = f.placement[g.object[k]].to_world;
    const Mesh& mesh = s.objects[g.object[k]].mesh;
    for (std::uint32_t p : spheres[k].prims) {
      const Tri& t = mesh.triangles[p];
      for (int i = 0; i < 4; ++i) {
        double u = unit(rng), v = unit(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        const Vec3d q = m.point(mesh.vertices[t[0]] + (mesh.vertices[t[1]] - mesh.vertices[t[0]]) * u +
                                (mesh.vertices[t[2]] - mesh.vertices[t[0]]) * v);
        ++points;
        REQUIRE(b.contains(Box<double>{q, q}));
      }
    }
  }
  CHECK(points > 2000);
}

TEST_CASE("top: a tree is rebuilt only when its unit's spheres change, refitted every frame", "[top]") {
  const Scene s = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  const auto spheres = make_spheres(s, 2);
  const SceneGeometry<float> g = build_geometry<float>(s, spheres, Accel::brute);
  TopTree tree;
  IuRegisters<float> regs;
  std::uint64_t built = 0;
  const std::vector<std::uint32_t> five{0, 3, 9, 17, 30}, six{0, 3, 9, 17, 30, 41};
  for (int frame : {0, 5, 10}) {
    const FrameSetup<float> f = setup_frame(s, g, frame);
    regs.load(f, g, five);
    CHECK(load_top(regs, tree, five, f, g, &built) == 9);  // refitted: 2 x 5 - 1 nodes
    REQUIRE(regs.top.size() == 9);
    // The root's box holds every leaf's, and each leaf names one register entry.
    std::vector<int> named(5, 0);
    for (const TopNode<float>& n : regs.top) {
      CHECK(regs.top[0].box.contains(n.box));
      if (n.leaf) ++named.at(n.offset);
    }
    CHECK(named == std::vector<int>(5, 1));
  }
  CHECK(built == 9);  // built once, for frame 0
  const FrameSetup<float> f = setup_frame(s, g, 11);
  regs.load(f, g, six);
  load_top(regs, tree, six, f, g, &built);
  CHECK(built == 9 + 11);  // the unit's spheres changed: rebuilt
}
