// Split by extent (balance/extent_split.h), the format's default split, and world-space
// sizes in the balance estimates.
#include "balance/extent_split.h"
#include "balance/policy.h"
#include "balance/spheres.h"
#include "ref/frame_setup.h"
#include "ref/reference.h"
#include "base/error.h"
#include "scene/generate.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <numeric>

using namespace oprt;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<std::uint32_t> all_of(const Mesh& m) {
  std::vector<std::uint32_t> v(m.triangles.size());
  std::iota(v.begin(), v.end(), 0u);
  return v;
}

void add_triangle(Mesh& m, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const auto i = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {a, b, c});
  m.triangles.push_back({i, i + 1, i + 2});
}

// Triangle (x - 1, 0, 0), (x + 1, 0, 0), (x, 1, 0): its first two corners are a diameter
// of its minimal sphere, centre (x, 0, 0), radius 1.
void add_diametric(Mesh& m, double x) { add_triangle(m, {x - 1, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}); }

Object object(const std::string& name, Mesh mesh, const Affine<double>& m = Affine<double>::identity()) {
  return {name, 0, std::move(mesh), std::make_shared<StaticMotion>(m), nullptr};
}

Scene scene_of(std::vector<Object> objects) {
  Scene s;
  s.materials.push_back({"grey", Vec3d(0.8), Vec3d(0), 1});
  s.lights.push_back({{0, 5, 5}, Vec3d(1), nullptr});
  s.objects = std::move(objects);
  s.camera = std::make_shared<FixedCamera>(Camera{});  // the eye at (0, 0, 5)
  return s;
}

}  // namespace

TEST_CASE("extent split: two distant pieces land in different spheres whatever their order in the mesh",
          "[balance][extent]") {
  // Two closed cubes of side 1, 20 apart, their 12 triangles each interleaved in the mesh.
  // A cube is compact (its halves by any plane have its radius): it stays one sphere.
  const Mesh a = box(Vec3d(1), 1);
  Mesh m;
  for (std::uint32_t t = 0; t < a.triangles.size(); ++t)
    for (double x : {0.0, 20.0}) {
      const Tri& tri = a.triangles[t];
      add_triangle(m, a.vertices[tri[0]] + Vec3d(x, 0, 0), a.vertices[tri[1]] + Vec3d(x, 0, 0),
                   a.vertices[tri[2]] + Vec3d(x, 0, 0));
    }
  std::vector<std::uint32_t> even, odd;
  for (std::uint32_t t = 0; t < 24; ++t) (t % 2 ? odd : even).push_back(t);
  ExtentCosts c;
  c.hull_area = 2 * (21 + 21 + 1);  // the hull of both cubes: a 21 x 1 x 1 box
  const auto parts = split_by_extent(m, all_of(m), c);
  REQUIRE(parts.size() == 2);
  CHECK(parts[0] == even);  // x = 0 first: tree order, lower side first
  CHECK(parts[1] == odd);
  // One cube alone is not split.
  Mesh one = box(Vec3d(1), 1);
  CHECK(split_by_extent(one, all_of(one), c).size() == 1);
}

TEST_CASE("extent split: the stopping rule's boundary", "[balance][extent]") {
  // n diametric triangles at x = -d and n at x = +d (radius 1 each). Together their minimal
  // sphere has radius R = d + 1 (the outer corners are a diameter; the apexes lie at
  // sqrt(d^2 + 1) < d + 1). With the hull's area H, a sphere of radius r costs a ray
  //   E = (4 pi r^2 / H)(transform + N triangle)     (below 1 of H: no clamp)
  // and the split pays iff 2 E(1, n) + sphere < E(d + 1, 2 n), i.e. iff
  //   (d + 1)^2 > (sphere H / (4 pi) + 2 (transform + n triangle)) / (transform + 2 n triangle).
  const ExtentCosts c{9, 19, 14.25, 4 * kPi * 400};
  for (int n : {1, 4}) {
    const double tn = c.transform + n * c.triangle, t2n = c.transform + 2 * n * c.triangle;
    const double d_star = std::sqrt((c.sphere * c.hull_area / (4 * kPi) + 2 * tn) / t2n) - 1;
    INFO("n " << n << ", boundary d = " << d_star);
    REQUIRE(d_star + 1 < 20);  // R within the hull's radius: no clamp
    for (double f : {0.99, 1.01}) {
      Mesh m;
      for (int i = 0; i < n; ++i) add_diametric(m, -d_star * f);
      for (int i = 0; i < n; ++i) add_diametric(m, d_star * f);
      const auto parts = split_by_extent(m, all_of(m), c);
      CHECK(parts.size() == (f < 1 ? 1u : 2u));
    }
  }
  // A single triangle, or copies of one (no gap between centroids), cannot be cut.
  Mesh same;
  for (int i = 0; i < 5; ++i) add_diametric(same, 3);
  CHECK(split_by_extent(same, all_of(same), c).size() == 1);
}

TEST_CASE("extent split: every triangle in exactly one sphere and the kitchen's room-wide groups are split",
          "[balance][extent]") {
  const std::string kitchen = std::string(OPRT_SHARED_DIR) + "/bart/kitchen/kitchen.aff";
  INFO("BART kitchen expected at " << kitchen);
  REQUIRE(std::filesystem::exists(kitchen));
  AffOptions whole;
  whole.max_object_triangles = 0;  // the loader keeps each material group whole
  LoadOptions load;
  load.aff = whole;
  const Scene s = load_scene(kitchen, load);
  const auto spheres = make_spheres(s, 1, SplitRule::balanced_san, ObjectSplit::extent);
  std::vector<std::vector<int>> seen(s.objects.size());
  for (std::size_t o = 0; o < s.objects.size(); ++o) seen[o].assign(s.objects[o].mesh.triangles.size(), 0);
  double largest = 0;
  for (const SphereDef& d : spheres) {
    for (std::uint32_t t : d.prims) ++seen[d.object][t];
    if (d.prims.size() > 100) largest = std::max(largest, d.world_radius());
  }
  for (const auto& v : seen) CHECK(std::all_of(v.begin(), v.end(), [](int k) { return k == 1; }));
  // Under the count rule two material groups of 1,640 and 2 x 2,613 triangles had spheres of
  // radius 2.6 around the whole room (docs/results.md); split by extent, no sphere of more
  // than 100 triangles is a third of that.
  CHECK(largest < 0.9);
}

TEST_CASE("split count keeps the spheres of before: one per object as the loader split it", "[balance][extent]") {
  const std::string kitchen = std::string(OPRT_SHARED_DIR) + "/bart/kitchen/kitchen.aff";
  INFO("BART kitchen expected at " << kitchen);
  REQUIRE(std::filesystem::exists(kitchen));
  const Scene s = load_scene(kitchen);  // max_object_triangles 4,096, as before
  const auto spheres = make_spheres(s, 1, SplitRule::balanced_san, ObjectSplit::count);
  // Pinned from `oprt info kitchen.aff` before split by extent existed (commit 9f58864).
  REQUIRE(spheres.size() == 62);
  const std::vector<std::size_t> prims = {
      2,    2,    406,  108,  78,   268,  1640, 2613, 2613, 2,    66,   296,  615,  3519, 3519, 3519,
      3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 3519, 2784, 2784, 2592,
      2592, 2592, 2592, 2100, 2100, 2100, 2100, 2100, 2100, 2100, 2100, 3264, 2,    2328, 1502, 72,
      2,    1406, 256,  188,  216,  16,   410,  480,  410,  480,  410,  480,  410,  480};
  double radii = 0;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    CHECK(spheres[i].object == i);
    CHECK(spheres[i].prims.size() == prims[i]);
    CHECK(spheres[i].prims.size() == s.objects[i].mesh.triangles.size());
    radii += spheres[i].local.r;
  }
  CHECK(radii == Approx(40.2722).margin(5e-5));
  CHECK(spheres[7].local.r == Approx(2.6514).margin(5e-5));
  CHECK(spheres[7].local.c.x == Approx(1.110).margin(5e-4));
}

TEST_CASE("the split's default follows the format: extent for BART and glTF and count for oprt JSON",
          "[balance][extent]") {
  CHECK(object_split_named("", "a/kitchen.aff") == ObjectSplit::extent);
  CHECK(object_split_named("", "box.GLB") == ObjectSplit::extent);
  CHECK(object_split_named("", "box.gltf") == ObjectSplit::extent);
  CHECK(object_split_named("", "paper_room.json") == ObjectSplit::count);
  CHECK(object_split_named("count", "kitchen.aff") == ObjectSplit::count);
  CHECK(object_split_named("extent", "paper_room.json") == ObjectSplit::extent);
  CHECK_THROWS_AS(object_split_named("size", "kitchen.aff"), InputError);
  // The paper's scenes: their objects as written, one sphere each.
  const Scene room = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  CHECK(make_spheres(room, 1, SplitRule::balanced_san, object_split_named("", room.source)).size() ==
        room.objects.size());
}

TEST_CASE("the split changes the spheres and never the image", "[balance][extent]") {
  const Scene s = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  const int n = 24;
  const auto count = make_spheres(s, 1, SplitRule::balanced_san, ObjectSplit::count);
  const auto extent = make_spheres(s, 1, SplitRule::balanced_san, ObjectSplit::extent);
  REQUIRE(extent.size() > count.size());
  const FrameResult a = render_reference(s, build_geometry<float>(s, count), 12, n, n);
  const FrameResult b = render_reference(s, build_geometry<float>(s, extent), 12, n, n);
  CHECK(a.image == b.image);
  CHECK(b.work.total().tri_tests() < a.work.total().tri_tests());
}

TEST_CASE("world size: a scaled object is weighed by its size in the scene and not in its own units",
          "[balance][world]") {
  // The same cube twice at x = 3: written at side 0.001 under a scale of 1,000, and written
  // at side 1 with no scale (the kitchen's toy-car wheels are written at radius 0.0005).
  const Affine<double> place = translate({3, 0, 0});
  const Scene scaled = scene_of({object("small", box(Vec3d(0.001), 1), place * scale(Vec3d(1000)))});
  const Scene plain = scene_of({object("unit", box(Vec3d(1), 1), place)});
  const auto ss = make_spheres(scaled, 1), sp = make_spheres(plain, 1);
  REQUIRE(ss.size() == 1);
  REQUIRE(sp.size() == 1);
  const double r = std::sqrt(3.0) / 2;  // the unit cube's half diagonal
  // max_stretch rounds up by 1e-9 (affine.h): the scale is 1,000 to 1e-8.
  CHECK(ss[0].local.r == Approx(r / 1000).epsilon(1e-12));
  CHECK(ss[0].scale == Approx(1000).epsilon(1e-8));
  CHECK(ss[0].world_radius() == Approx(r).epsilon(1e-8));
  CHECK(ss[0].surface_area() == Approx(4 * kPi * r * r).epsilon(1e-8));
  CHECK(ss[0].sa_n() == Approx(4 * kPi * r * r * 12).epsilon(1e-8));
  CHECK(ss[0].sa_n() == Approx(sp[0].sa_n()).epsilon(1e-12));
  // sa_n weights (policy.h): the same for both.
  CHECK(sa_n_weights(scaled, ss)[0] == Approx(sa_n_weights(plain, sp)[0]).epsilon(1e-12));
  // The view estimate takes the world spheres the GPP computes per frame (frame_setup):
  // the radius it holds is the world radius, up to its rounding margin.
  const SceneGeometry<float> g = build_geometry<float>(scaled, ss);
  const FrameSetup<float> f = setup_frame(scaled, g, 0);
  CHECK(f.world_sphere[0].r >= r);
  CHECK(f.world_sphere[0].r == Approx(r).epsilon(1e-4));  // margin: 64 ulps of |eye| = 5
  // Split by extent judges the object at its world size too: the scaled and the plain
  // pair of distant cubes split alike.
  Mesh pair = box(Vec3d(1), 1), far = box(Vec3d(1), 1);
  for (Vec3d& v : far.vertices) v.x += 20;
  pair.append(far);
  Mesh tiny = pair;
  for (Vec3d& v : tiny.vertices) v /= 1000.0;
  const Scene big = scene_of({object("pair", pair)});
  const Scene small = scene_of({object("pair", tiny, scale(Vec3d(1000)))});
  const auto eb = make_spheres(big, 1, SplitRule::balanced_san, ObjectSplit::extent);
  const auto es = make_spheres(small, 1, SplitRule::balanced_san, ObjectSplit::extent);
  REQUIRE(eb.size() == 2);
  REQUIRE(es.size() == 2);
  for (int i = 0; i < 2; ++i) CHECK(es[i].prims == eb[i].prims);
}

TEST_CASE("world size: the kitchen's toy-car wheels have a sphere area and an SA x N", "[balance][world]") {
  const std::string kitchen = std::string(OPRT_SHARED_DIR) + "/bart/kitchen/kitchen.aff";
  INFO("BART kitchen expected at " << kitchen);
  REQUIRE(std::filesystem::exists(kitchen));
  const Scene s = load_scene(kitchen);
  int wheels = 0;
  for (const SphereDef& d : make_spheres(s, 1)) {
    const std::string& name = s.objects[d.object].name;
    if (name.find("wheel") == std::string::npos) continue;
    ++wheels;
    INFO(name << " local radius " << d.local.r << ", world " << d.world_radius());
    CHECK(d.local.r < 0.001);         // written in other units ...
    CHECK(d.world_radius() > 0.015);  // ... and scaled up to a wheel's size in the kitchen
    CHECK(d.sa_n() > 1);
  }
  CHECK(wheels == 8);
}
