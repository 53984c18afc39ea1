// --accel bvh against brute force: the same nearest hit (t, object, prim, u, v bit for bit)
// and the same occlusion, on the paper's scenes and on triangle soups built to hit the hard
// cases (exact ties, rays through vertices and shared edges, rays in a triangle's plane).
#include "ref/reference.h"
#include "scene/load.h"
#include "test_scenes.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

namespace {

Scene paper(const std::string& name) { return load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/" + name); }

Object object_of(Mesh m, const std::string& name) {
  return Object{name, 0, std::move(m), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr};
}

// Four objects: random triangles; a fan grid in z = 0 (shared edges and vertices); right
// triangles with power-of-two legs stacked in z = 2, overlapping (a ray hits several at
// bit-identical t: n = (0, 0, 2^k) makes every product exact); axis-aligned walls (x = 3).
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
  Mesh wall;
  for (int i = 0; i < 40; ++i) {
    const double y = cell(rng), z = cell(rng);
    const auto b = static_cast<std::uint32_t>(wall.vertices.size());
    wall.vertices.insert(wall.vertices.end(), {{3, y, z}, {3, y + 2, z}, {3, y, z + 2}});
    wall.triangles.push_back({b, b + 1, b + 2});
  }
  s.objects = {object_of(random, "random"), object_of(grid, "grid"), object_of(stack, "stack"), object_of(wall, "wall")};
  return s;
}

template <typename T>
IuRegisters<T> all_spheres(const SceneGeometry<T>& g, const FrameSetup<T>& f) {
  std::vector<std::uint32_t> all(g.sphere_count());
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  IuRegisters<T> r;
  r.load(f, g, all);
  return r;
}

template <typename T>
bool same(const HitRecord<T>& a, const HitRecord<T>& b) {
  return a.t == b.t && a.object == b.object && a.prim == b.prim && a.u == b.u && a.v == b.v;
}

template <typename T>
void check_paper_images(const std::string& name, int size, int subdivide, Kernel kernel = Kernel::moller) {
  const Scene s = paper(name);
  const auto spheres = make_spheres(s, subdivide);
  const auto brute = build_geometry<T>(s, spheres, kernel, Accel::brute);
  const auto bvh = build_geometry<T>(s, spheres, kernel, Accel::bvh);
  REQUIRE(bvh.has_bvh());
  for (int frame : {0, 17}) {
    INFO(name << " frame " << frame << " subdivide " << subdivide);
    const FrameResult a = render_reference(s, brute, frame, size, size);
    const FrameResult b = render_reference(s, bvh, frame, size, size);
    CHECK(a.image.r == b.image.r);
    CHECK(a.image.g == b.image.g);
    CHECK(a.image.b == b.image.b);
    CHECK(a.image.z == b.image.z);
    CHECK(a.image.object == b.image.object);
    CHECK(a.image.prim == b.image.prim);
    CHECK(a.image == b.image);  // bit for bit, NaN-safe
    // Same rays, same sphere tests and transforms; far fewer triangle tests.
    CHECK(a.work.rays == b.work.rays);
    const WorkCounts wa = a.work.total(RayKind::primary), wb = b.work.total(RayKind::primary);
    CHECK(wa.sphere_tests == wb.sphere_tests);
    CHECK(wa.transforms == wb.transforms);
    CHECK(wb.box_setups == wb.transforms);  // every entered sphere has a tree
    CHECK(wb.tri_tests() * 10 < wa.tri_tests());
    CHECK(wa.box_tests == 0);
  }
}

}  // namespace

TEMPLATE_TEST_CASE("bvh: reference images equal brute force bit for bit on paper_room", "[bvh][reference]", float,
                   double) {
  check_paper_images<TestType>("paper_room.json", 40, 1);
}

TEMPLATE_TEST_CASE("bvh: reference images equal brute force bit for bit on paper_polygons", "[bvh][reference]", float,
                   double) {
  check_paper_images<TestType>("paper_polygons.json", 32, 1);
}

TEST_CASE("bvh: reference images equal brute force on paper_room subdivided into 8", "[bvh][reference]") {
  check_paper_images<float>("paper_room.json", 32, 8);
}

TEMPLATE_TEST_CASE("bvh: with the watertight kernel reference images equal brute force bit for bit",
                   "[bvh][reference][watertight]", float, double) {
  check_paper_images<TestType>("paper_room.json", 40, 1, Kernel::watertight);
  check_paper_images<TestType>("paper_polygons.json", 32, 1, Kernel::watertight);
}

namespace {
// The box padding's argument (scene_geometry.cpp bvh_pad) covers every kernel's vertex
// rounding; checked here for each kernel on rays aimed at vertices, edges and planes.
template <typename T>
void check_soup(Kernel kernel) {
  std::mt19937_64 rng(2024);
  const Scene s = soup(rng);
  const auto spheres = make_spheres(s, 1);
  const auto brute = build_geometry<T>(s, spheres, kernel, Accel::brute);
  const auto bvh = build_geometry<T>(s, spheres, kernel, Accel::bvh);
  const FrameSetup<T> fb = setup_frame(s, brute, 0), fv = setup_frame(s, bvh, 0);
  const IuRegisters<T> rb = all_spheres(brute, fb), rv = all_spheres(bvh, fv);
  std::uniform_real_distribution<double> pos(-14, 14), unit(0, 1), len(0.1, 30);
  auto none = [](const SphereVisit&) {};
  // Named hard cases, counted.
  int through_vertex = 0, through_edge = 0, in_plane = 0, ties = 0, hits = 0, occluded = 0;
  for (int i = 0; i < 40000; ++i) {
    const Object& obj = s.objects[i % s.objects.size()];
    const Tri& tri = obj.mesh.triangles[(i / 4) % obj.mesh.triangles.size()];
    const Vec3d a = obj.mesh.vertices[tri[0]], b = obj.mesh.vertices[tri[1]], c = obj.mesh.vertices[tri[2]];
    Vec3d target;
    const int kind = i % 5;
    if (kind == 0) target = a, ++through_vertex;
    else if (kind == 1) target = (a + b) * 0.5, ++through_edge;
    else target = a + (b - a) * unit(rng) * 0.5 + (c - a) * unit(rng) * 0.5;
    Vec3d o(pos(rng), pos(rng), pos(rng));
    if (kind == 4 && (obj.name == "grid" || obj.name == "stack")) {  // in the plane of the triangles
      o.z = a.z;
      ++in_plane;
    }
    Vec3d d = target - o;
    if (dot3(d, d) == 0) continue;
    d = d / std::sqrt(dot3(d, d));
    const Ray<T> ray{Vec3<T>(o), Vec3<T>(d), kInf<T>};
    const HitRecord<T> hb = trace_nearest(brute, rb, ray, none), hv = trace_nearest(bvh, rv, ray, none);
    INFO("ray " << i << " kind " << kind);
    REQUIRE(same(hb, hv));
    hits += hb.valid();
    // A tie: another triangle of the same object hit at exactly the same t (brute force
    // keeps the lowest prim; so must the BVH). Counted with Moller's test.
    if (hb.valid() && kernel == Kernel::moller) {
      int at_t = 0;
      const Object& hit_obj = s.objects[hb.object];
      for (const Tri& t : hit_obj.mesh.triangles) {
        const auto m = prepare_moller<T>(hit_obj.mesh.vertices[t[0]], hit_obj.mesh.vertices[t[1]], hit_obj.mesh.vertices[t[2]]);
        const TriangleHit<T> h = intersect_moller(ray, m);
        at_t += h.hit && h.t == hb.t;
      }
      ties += at_t > 1;
    }
    // Shadow-like rays: any hit within a random extent.
    const Ray<T> seg{Vec3<T>(o), Vec3<T>(d), static_cast<T>(len(rng))};
    const bool ob = trace_any(brute, rb, seg, none), ov = trace_any(bvh, rv, seg, none);
    REQUIRE(ob == ov);
    occluded += ob;
  }
  INFO("hits " << hits << ", ties " << ties << ", through vertices " << through_vertex << ", through edges "
               << through_edge << ", in a triangle's plane " << in_plane << ", occluded " << occluded);
  CHECK(hits > 20000);
  if (kernel == Kernel::moller) CHECK(ties > 500);
  CHECK(in_plane > 1000);
  CHECK(occluded > 5000);
}
}  // namespace

TEMPLATE_TEST_CASE("bvh: on triangle soups with hard rays the nearest hit and occlusion equal brute force",
                   "[bvh][hard]", float, double) {
  check_soup<TestType>(Kernel::moller);
}

TEMPLATE_TEST_CASE("bvh: on triangle soups the watertight kernel's nearest hit and occlusion equal brute force",
                   "[bvh][hard][watertight]", float, double) {
  check_soup<TestType>(Kernel::watertight);
}

TEST_CASE("bvh: a sphere's work depends only on the ray and the sphere", "[bvh]") {
  std::mt19937_64 rng(5);
  const Scene s = soup(rng);
  const auto g = build_geometry<float>(s, make_spheres(s, 2), Accel::bvh);
  const FrameSetup<float> f = setup_frame(s, g, 0);
  const IuRegisters<float> all = all_spheres(g, f);
  std::vector<IuRegisters<float>> single(g.sphere_count());
  for (std::uint32_t k = 0; k < g.sphere_count(); ++k) single[k].load(f, g, {k});
  std::uniform_real_distribution<double> pos(-14, 14);
  std::uint64_t boxes = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3d o(pos(rng), pos(rng), pos(rng)), t(pos(rng) / 2, pos(rng) / 2, pos(rng) / 2);
    const Ray<float> ray{Vec3f(o), Vec3f(glm::normalize(t - o)), kInf<float>};
    std::vector<WorkCounts> together(g.sphere_count()), alone(g.sphere_count());
    trace_nearest(g, all, ray, AccumulateWork{together.data()});
    for (std::uint32_t k = 0; k < g.sphere_count(); ++k) trace_nearest(g, single[k], ray, AccumulateWork{alone.data()});
    for (std::uint32_t k = 0; k < g.sphere_count(); ++k) {
      REQUIRE(together[k] == alone[k]);
      boxes += alone[k].box_tests;
    }
  }
  CHECK(boxes > 3000);
}

TEST_CASE("bvh: deforming objects are refitted and still agree with brute force", "[bvh]") {
  // The wall of shadow_box bends over the frames (a VertexMotion in code).
  struct Bend final : VertexMotion {
    Mesh rest;
    void at(double frame, std::vector<Vec3d>& v) const override {
      v = rest.vertices;
      for (Vec3d& p : v) p.z += 0.3 * frame * std::sin(p.x) * std::cos(p.y);
    }
  };
  Scene s = test::shadow_box(32);
  Mesh fine;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      const double x0 = -10 + 1.25 * i, y0 = -10 + 1.25 * j;
      const auto b = static_cast<std::uint32_t>(fine.vertices.size());
      fine.vertices.insert(fine.vertices.end(), {{x0, y0, 0}, {x0 + 1.25, y0, 0}, {x0 + 1.25, y0 + 1.25, 0}, {x0, y0 + 1.25, 0}});
      fine.triangles.push_back({b, b + 1, b + 2});
      fine.triangles.push_back({b, b + 2, b + 3});
    }
  auto bend = std::make_shared<Bend>();
  bend->rest = fine;
  s.objects[0].mesh = fine;
  s.objects[0].deform = bend;
  auto brute = build_geometry<float>(s, make_spheres(s, 1), Accel::brute);
  auto bvh = build_geometry<float>(s, make_spheres(s, 1), Accel::bvh);
  for (int frame : {1, 3}) {
    const std::uint64_t bytes_brute = update_deforming(brute, s, frame);
    const std::uint64_t bytes_bvh = update_deforming(bvh, s, frame);
    CHECK(bytes_bvh == bytes_brute + std::uint64_t{bvh.nodes_in(0)} * SceneGeometry<float>::kNodeBytes);
    const FrameResult a = render_reference(s, brute, frame, 32, 32), b = render_reference(s, bvh, frame, 32, 32);
    CHECK(a.image == b.image);
    CHECK(b.work.total().box_tests > 0);
  }
}
