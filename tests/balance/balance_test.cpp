#include "balance/dynamic.h"
#include "balance/hull_area.h"
#include "balance/policy.h"
#include "balance/spheres.h"
#include "balance/subdivide.h"
#include "analytic/engine.h"
#include "ref/reference.h"
#include "scene/generate.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

using namespace oprt;

namespace {
double makespan(const Assignment& a, const std::vector<double>& w) {
  const auto l = unit_loads(a, w);
  return *std::max_element(l.begin(), l.end());
}

// The best makespan over every assignment of the items to `m` units (m^n of them).
double optimum(const std::vector<double>& w, int m) {
  const std::size_t n = w.size();
  std::vector<int> unit(n, 0);
  double best = 1e300;
  for (;;) {
    std::vector<double> load(m, 0);
    for (std::size_t i = 0; i < n; ++i) load[unit[i]] += w[i];
    best = std::min(best, *std::max_element(load.begin(), load.end()));
    std::size_t i = 0;
    while (i < n && ++unit[i] == m) unit[i++] = 0;
    if (i == n) return best;
  }
}

Scene room() { return load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json"); }

constexpr double kPi = 3.14159265358979323846;

Object static_object(const std::string& name, Mesh mesh) {
  return {name, 0, std::move(mesh), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr};
}

// A cube of side 2 and, at its centre, a cube of side 0.2; one light at (0, 0, 10).
Scene nested_cubes() {
  Scene s;
  s.materials.push_back({"grey", Vec3d(0.8), Vec3d(0), 1});
  s.lights.push_back({{0, 0, 10}, Vec3d(1), nullptr});
  s.objects.push_back(static_object("big", box(Vec3d(2), 1)));
  s.objects.push_back(static_object("small", box(Vec3d(0.2), 1)));
  return s;
}
}  // namespace

TEST_CASE("assignments are partitions under every static policy", "[balance]") {
  const Scene s = room();
  for (int k : {1, 3, 8}) {
    const auto spheres = make_spheres(s, k);
    for (std::size_t units : {1, 5, 32, 64})
      for (const char* policy : {"paper", "round_robin", "sa_n"}) {
        INFO(policy << " k " << k << " units " << units);
        const Assignment a = static_assignment(policy, s, spheres, units_for(spheres.size(), units));
        CHECK(a.is_partition(spheres.size()));
        CHECK(a.units() == std::min(units, spheres.size()));
        for (const auto& u : a.unit) CHECK_FALSE(u.empty());  // no idle unit instantiated
      }
  }
}

TEST_CASE("lpt is within 4/3 - 1/(3m) of the optimum on exhaustively solved cases", "[balance]") {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> size(1, 100);
  int cases = 0, optimal = 0;
  double worst = 1;
  for (int m = 2; m <= 3; ++m)
    for (int n = m + 1; n <= 9; ++n)
      for (int trial = 0; trial < 12; ++trial) {
        std::vector<double> w(n);
        for (double& x : w) x = trial % 4 == 0 ? std::round(size(rng) / 20) + 1 : size(rng);  // some ties
        const double lpt = makespan(assign_weighted(w, m), w), opt = optimum(w, m);
        const double bound = 4.0 / 3 - 1.0 / (3 * m);
        CHECK(lpt <= bound * opt * (1 + 1e-12));
        worst = std::max(worst, lpt / opt);
        optimal += lpt == opt;
        ++cases;
      }
  INFO("worst lpt/opt " << worst << ", optimal in " << optimal << " of " << cases);
  CHECK(cases == 2 * 7 * 12 - 12);
  CHECK(worst < 4.0 / 3);
  // The classic tight case: 2m + 1 jobs 2m-1, 2m-1, 2m-2, 2m-2, ..., m, m, m on m units.
  const int m = 3;
  const std::vector<double> tight = {5, 5, 4, 4, 3, 3, 3};
  CHECK(makespan(assign_weighted(tight, m), tight) == 11);
  CHECK(optimum(tight, m) == 9);  // 11 / 9 = 4/3 - 1/9
}

TEST_CASE("subdivision puts every primitive in exactly one sub-sphere that encloses it", "[balance]") {
  const Scene s = room();
  for (SplitRule rule : {SplitRule::balanced_san, SplitRule::median})
    for (int k : {2, 5, 8, 13}) {
      std::size_t total = 0;
      for (std::uint32_t o = 0; o < s.objects.size(); ++o) {
        const Mesh& m = s.objects[o].mesh;
        const auto clusters = subdivide(m, k, rule);
        CHECK(clusters.size() == std::min<std::size_t>(k, m.triangles.size()));
        std::vector<int> seen(m.triangles.size(), 0);
        for (const auto& c : clusters) {
          REQUIRE_FALSE(c.empty());
          const Sphere<double> b = bound_triangles(m, c);
          for (std::uint32_t t : c) {
            ++seen[t];
            for (std::uint32_t v : m.triangles[t]) CHECK(glm::length(m.vertices[v] - b.c) <= b.r * (1 + 1e-12));
          }
        }
        CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
        total += m.triangles.size();
      }
      CHECK(total == 35108);
    }
}

TEST_CASE("subdivision lowers the room's total SA x N and the balanced rule lowers it most", "[balance]") {
  const Scene s = room();
  auto total = [&](int k) {
    double t = 0;
    for (const SphereDef& d : make_spheres(s, k)) t += d.sa_n();
    return t;
  };
  const double one = total(1), eight = total(8);
  CHECK(eight < one / 2);
  double median = 0;
  for (std::uint32_t o = 0; o < s.objects.size(); ++o)
    for (const auto& c : subdivide(s.objects[o].mesh, 8, SplitRule::median)) {
      const Sphere<double> b = bound_triangles(s.objects[o].mesh, c);
      median += 4 * 3.14159265358979323846 * b.r * b.r * c.size();
    }
  CHECK(eight < median);
}

TEST_CASE("view weights by hand", "[balance]") {
  Camera cam;
  cam.eye = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.fov_y_deg = 90;
  const std::vector<Sphere<double>> spheres = {
      {{0, 0, 0}, 2},     // the eye inside: every pixel
      {{0, 0, 10}, 1},    // behind the camera: no primary ray
      {{0, 0, -10}, 1},   // ahead: pi r^2 / d^2 of the view's solid angle
  };
  ViewCostModel m{0, 0, 1};  // count triangle tests only
  const auto w = view_weights(spheres, {1, 1, 1}, cam, 100, 100, {}, m);
  CHECK(w[0] == Approx(100 * 100));
  CHECK(w[1] == 0);
  const double view_sr = 4 * std::asin(std::sin(3.14159265358979323846 / 4) * std::sin(3.14159265358979323846 / 4));
  // The cap seen from 10 away, r = 1: 2 pi (1 - sqrt(0.99)) sr.
  CHECK(w[2] == Approx(1e4 * (2 * 3.14159265358979323846 * (1 - std::sqrt(0.99))) / view_sr).epsilon(1e-12));
  // A light inside a sphere sends it every lit pixel's shadow ray.
  const auto lit = view_weights(spheres, {1, 1, 1}, cam, 100, 100, {{{0, 0, 10}, Vec3d(1), nullptr}}, m);
  CHECK(lit[1] > w[1]);
}

TEST_CASE("relabelling keeps the partition and moves no more geometry", "[balance]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(1, 10);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> w1(40), w2(40);
    std::vector<std::uint64_t> bytes(40);
    for (int i = 0; i < 40; ++i) w1[i] = u(rng), w2[i] = w1[i] * u(rng) / 5, bytes[i] = 48 * (1 + i % 7);
    const Assignment prev = assign_weighted(w1, 6);
    const Assignment next = assign_weighted(w2, 6);
    const Assignment kept = keep_in_place(next, prev, bytes);
    CHECK(kept.is_partition(40));
    CHECK(unit_loads(kept, w2) != std::vector<double>{});  // same sets, other labels:
    auto a = unit_loads(kept, w2), b = unit_loads(next, w2);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    CHECK(a == b);
    CHECK(moved_bytes(kept, prev, bytes) <= moved_bytes(next, prev, bytes));
  }
  // An unchanged partition with shuffled labels moves nothing once relabelled.
  const Assignment prev = assign_round_robin(12, 4);
  Assignment shuffled = prev;
  std::reverse(shuffled.unit.begin(), shuffled.unit.end());
  CHECK(moved_bytes(keep_in_place(shuffled, prev, std::vector<std::uint64_t>(12, 48)), prev,
                    std::vector<std::uint64_t>(12, 48)) == 0);
}

TEST_CASE("the image is the same under every policy and subdivision", "[balance]") {
  const Scene s = room();
  const int n = 24;
  const SceneGeometry<float> g1 = build_geometry<float>(s, make_spheres(s, 1));
  const FrameImage ref = render_reference(s, g1, 12, n, n).image;
  for (int k : {1, 8})
    for (const char* policy : {"paper", "round_robin", "sa_n", "spatial"}) {
      INFO(policy << " k " << k);
      const auto spheres = make_spheres(s, k);
      const SceneGeometry<float> g = build_geometry<float>(s, spheres);
      Arch arch;
      arch.ius = 7;
      analytic::AnalyticEngine<float> engine(s, g, arch);
      engine.assign(static_assignment(policy, s, spheres, units_for(spheres.size(), 7)));
      FrameImage img(n, n);
      timing::FrameCommand cmd;
      cmd.frame = 12;
      cmd.to_world = object_matrices(s, 12);
      cmd.camera = s.camera->at(12);
      cmd.width = cmd.height = n;
      cmd.image = &img;
      engine.run_frame(cmd);
      CHECK(img == ref);
    }
}

TEST_CASE("convex hull areas by hand", "[balance]") {
  // A cube of side 2 with points inside it: area 24.
  std::vector<Vec3d> cube;
  for (int i = 0; i < 8; ++i) cube.push_back({i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1});
  cube.push_back({0, 0, 0});
  cube.push_back({0.5, -0.25, 0.9});
  CHECK(convex_hull_area(cube).value() == Approx(24).epsilon(1e-12));
  // The regular tetrahedron of edge sqrt(8) inside it: 4 equilateral faces, sqrt(3) * 8.
  const std::vector<Vec3d> tet = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  CHECK(convex_hull_area(tet).value() == Approx(8 * std::sqrt(3.0)).epsilon(1e-12));
  // No interior: no hull.
  CHECK_FALSE(convex_hull_area({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).has_value());
  CHECK_FALSE(convex_hull_area({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.2, 0}}).has_value());
}

TEST_CASE("sa_n weights by hand: Crofton against the hull, shadow rays by the light's solid angle", "[balance]") {
  const Scene s = nested_cubes();
  CHECK(scene_hull_area(s) == Approx(24).epsilon(1e-12));
  const auto spheres = make_spheres(s, 1);
  REQUIRE(spheres.size() == 2);
  REQUIRE(spheres[0].prims.size() == 12);
  REQUIRE(spheres[1].prims.size() == 12);
  const SaNCosts c;  // 9, 19, 14.25
  const auto w = sa_n_weights(s, spheres, c);
  const double body = 19 + 12 * 14.25;
  // Big cube: radius sqrt(3), area 12 pi > 24: every line through the hull meets it.
  // The light 10 away sees it under a cap of (1 - sqrt(1 - 3/100)) / 2 of all directions.
  CHECK(w[0] == Approx(2 * 9 + (1 + (1 - std::sqrt(0.97)) / 2) * body).epsilon(1e-6));
  // Small cube: radius 0.1 sqrt(3), area 0.12 pi, so 0.12 pi / 24 of the lines.
  CHECK(w[1] == Approx(2 * 9 + (0.12 * kPi / 24 + (1 - std::sqrt(1 - 0.03 / 100)) / 2) * body).epsilon(1e-6));
  // A flat scene has no hull with an interior: its minimal sphere's area stands in.
  Scene flat;
  Mesh quad;
  quad.vertices = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  flat.objects.push_back(static_object("quad", quad));
  CHECK(scene_hull_area(flat) == Approx(4 * kPi * 2).epsilon(1e-9));  // r = sqrt(2)
}

TEST_CASE("lpt by hand", "[balance]") {
  // By decreasing weight: 7 -> u0, 5 -> u1, 4 -> u1 (5 < 7), 3 -> u0 (7 < 9), 3 -> u1 (9 < 10).
  const Assignment a = assign_weighted({7, 5, 4, 3, 3}, 2);
  CHECK(a.unit[0] == std::vector<std::uint32_t>{0, 3});
  CHECK(a.unit[1] == std::vector<std::uint32_t>{1, 2, 4});
  // 12 against the optimum 11 ({7, 4} and {5, 3, 3}), within 4/3 - 1/6.
  CHECK(makespan(a, {7, 5, 4, 3, 3}) == 12);
  CHECK(optimum({7, 5, 4, 3, 3}, 2) == 11);
}

TEST_CASE("the balanced split cuts at the gap between clusters, the median split at the count", "[balance]") {
  // 30 small triangles spread over x in [0, 1], then 10 over x in [10, 11].
  Mesh m;
  auto add = [&](double x) {
    const auto b = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{x, 0, 0}, {x + 0.01, 0.1, 0}, {x, 0, 0.1}});
    m.triangles.push_back({b, b + 1, b + 2});
  };
  for (int i = 0; i < 30; ++i) add(i / 30.0);
  for (int i = 0; i < 10; ++i) add(10 + i / 10.0);
  std::vector<std::uint32_t> first(30), second(10);
  std::iota(first.begin(), first.end(), 0u);
  std::iota(second.begin(), second.end(), 30u);
  // Balanced: any cut other than at 30 leaves a piece spanning the 9-unit gap, whose
  // sphere costs more SA x N than both clusters' together.
  const auto balanced = subdivide(m, 2, SplitRule::balanced_san);
  REQUIRE(balanced.size() == 2);
  CHECK(((balanced[0] == first && balanced[1] == second) || (balanced[0] == second && balanced[1] == first)));
  // Median: 20 and 20, the second piece spanning the gap.
  const auto median = subdivide(m, 2, SplitRule::median);
  REQUIRE(median.size() == 2);
  CHECK(median[0].size() == 20);
  CHECK(median[1].size() == 20);
}

TEST_CASE("the paper's assignment gives each unit a contiguous block of spheres", "[balance]") {
  // Sphere s to unit floor(s x units / spheres): 10 spheres on 4 units are 0-2, 3-4, 5-7, 8-9.
  using Ids = std::vector<std::uint32_t>;
  CHECK(assign_paper(10, 4).unit == std::vector<Ids>{{0, 1, 2}, {3, 4}, {5, 6, 7}, {8, 9}});
  CHECK(assign_paper(4, 2).unit == std::vector<Ids>{{0, 1}, {2, 3}});
}

TEST_CASE("the median split cuts the longest axis of the centroids", "[balance]") {
  // Four small triangles at y = 0, 3, 1, 2 (ids 0 to 3), x and z the same: y is the longest
  // axis, and its median puts ids 0 and 2 (y = 0, 1) on one side, 1 and 3 on the other.
  Mesh m;
  for (double y : {0.0, 3.0, 1.0, 2.0}) {
    const auto b = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{0, y, 0}, {0.1, y, 0}, {0, y + 0.1, 0}});
    m.triangles.push_back({b, b + 1, b + 2});
  }
  auto parts = subdivide(m, 2, SplitRule::median);
  REQUIRE(parts.size() == 2);
  for (auto& p : parts) std::sort(p.begin(), p.end());
  std::sort(parts.begin(), parts.end());
  CHECK(parts == std::vector<std::vector<std::uint32_t>>{{0, 2}, {1, 3}});
}
