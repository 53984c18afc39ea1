// --balance spatial and what a partition buys (balance/spatial.h, balance/partition_quality.h):
// cases worked out by hand, sa_n's assignment at locality 0, and the room's fan-out.
#include "balance/partition_quality.h"
#include "balance/policy.h"
#include "balance/spatial.h"
#include "balance/spheres.h"
#include "scene/generate.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

namespace {

using Ids = std::vector<std::uint32_t>;

// A cube of side 1 centred at (x, 0, 0): area 6; n of them side by side span a box of
// area 2 (n + 1 + n) = 4 n + 2.
Box<double> cube_at(double x) { return {{x - 0.5, -0.5, -0.5}, {x + 0.5, 0.5, 0.5}}; }

std::vector<Box<double>> cubes_on_a_line(int n) {
  std::vector<Box<double>> b;
  for (int i = 0; i < n; ++i) b.push_back(cube_at(i));
  return b;
}

Scene room() { return load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json"); }

double fanout(const Assignment& a, const std::vector<Box<double>>& boxes) {
  return expected_fanout(unit_bounds(a, boxes), union_of(boxes));
}

}  // namespace

TEST_CASE("spatial: locality 1 gives spheres on a line to units in contiguous runs", "[balance][spatial]") {
  const auto boxes = cubes_on_a_line(8);
  const std::vector<double> equal(8, 1);
  const Assignment two = assign_spatial(boxes, equal, 2, 1);
  CHECK(two.unit == std::vector<Ids>{{0, 1, 2, 3}, {4, 5, 6, 7}});
  const Assignment four = assign_spatial(boxes, equal, 4, 1);
  CHECK(four.unit == std::vector<Ids>{{0, 1}, {2, 3}, {4, 5}, {6, 7}});
  // Four boxes of two cubes (area 10 each) in one of eight (area 34).
  const PartitionQuality q = partition_quality(four, boxes, equal);
  CHECK(q.fanout == Approx(40.0 / 34).epsilon(1e-12));
  CHECK(q.imbalance == 1);
  CHECK(q.unit_bound[1].lo.x == 1.5);
  CHECK(q.unit_bound[1].hi.x == 3.5);
  // sa_n's greedy deals them out in turn: every unit spans most of the line.
  const Assignment dealt = assign_spatial(boxes, equal, 4, 0);
  CHECK(dealt.unit == std::vector<Ids>{{0, 4}, {1, 5}, {2, 6}, {3, 7}});
  CHECK(fanout(dealt, boxes) == Approx(4 * 22.0 / 34).epsilon(1e-12));  // each spans 5 cubes: 4 x 5 + 2

  // By cost, not by count: of {4, 1, 1, 1, 1} the first alone is half.
  const auto five = cubes_on_a_line(5);
  CHECK(assign_spatial(five, {4, 1, 1, 1, 1}, 2, 1).unit == std::vector<Ids>{{0}, {1, 2, 3, 4}});
}

TEST_CASE("spatial: a sphere leaves a full region when the load it evens out outweighs the fan-out it adds",
          "[balance][spatial]") {
  // Cubes at x = 0..3 with costs {1, 3, 1, 1}, 2 units; mean load 3; the scene's box [-0.5, 3.5]
  // has area 18. Regions: of the cuts after 1, 2 or 3 cubes (lower sides 1, 4, 5; half is 3)
  // the one after 2 comes closest: {0, 1} (load 4) and {2, 3} (load 2).
  const auto boxes = cubes_on_a_line(4);
  const std::vector<double> w = {1, 3, 1, 1};
  CHECK(spatial_regions(boxes, w, 2) == std::vector<Ids>{{0, 1}, {2, 3}});
  // Heaviest first: cube 1 stays (unit 0 reaches the mean, 3). Cube 0 would take unit 0 one
  // third of a mean over: (1 - F) / 3. On unit 1 it is no load over, but it widens unit 1's
  // box from [1.5, 3.5] (area 10) to the whole scene (18): 8 / 18 of a fan-out over 2 units,
  // F x 2 / 9. It moves while F x 2 / 9 < (1 - F) / 3, that is while F < 3 / 5. Cubes 2 and 3
  // then stay in their region, unit 1 being below the mean.
  for (double f : {0.25, 0.5, 0.59}) {
    INFO("locality " << f);
    const Assignment a = assign_spatial(boxes, w, 2, f);
    CHECK(a.unit == std::vector<Ids>{{1}, {0, 2, 3}});
    const PartitionQuality q = partition_quality(a, boxes, w);
    CHECK(q.fanout == Approx((6.0 + 18) / 18).epsilon(1e-12));
    CHECK(q.imbalance == 1);
  }
  for (double f : {0.61, 0.9, 1.0}) {
    INFO("locality " << f);
    const Assignment a = assign_spatial(boxes, w, 2, f);
    CHECK(a.unit == std::vector<Ids>{{0, 1}, {2, 3}});
    const PartitionQuality q = partition_quality(a, boxes, w);
    CHECK(q.fanout == Approx(20.0 / 18).epsilon(1e-12));
    CHECK(q.imbalance == Approx(4.0 / 3).epsilon(1e-12));
  }
}

TEST_CASE("spatial: locality 0 is sa_n's assignment exactly", "[balance][spatial]") {
  const Scene s = room();
  for (int k : {1, 8}) {
    const auto spheres = make_spheres(s, k);
    for (std::size_t units : {5, 32}) {
      INFO("k " << k << " units " << units);
      const std::size_t n = units_for(spheres.size(), units);
      CHECK(static_assignment("spatial", s, spheres, n, {}, 0).unit == static_assignment("sa_n", s, spheres, n).unit);
    }
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 10);
  std::vector<Box<double>> boxes;
  std::vector<double> w;
  for (int i = 0; i < 50; ++i) {
    const Vec3d c(u(rng), u(rng), u(rng));
    boxes.push_back({c - 0.5, c + 0.5});
    w.push_back(std::floor(u(rng)));  // ties
  }
  CHECK(assign_spatial(boxes, w, 7, 0).unit == assign_weighted(w, 7).unit);
}

TEST_CASE("spatial: on the room at K = 8 locality 1 never has a larger fan-out than locality 0", "[balance][spatial]") {
  const Scene s = room();
  const auto spheres = make_spheres(s, 8);
  const auto boxes = sphere_world_boxes(s, spheres, 0);
  const auto w = sa_n_weights(s, spheres);
  for (std::size_t units : {2, 4, 8, 16, 32, 64}) {
    INFO(units << " units");
    const double tight = fanout(assign_spatial(boxes, w, units, 1), boxes);
    const double balanced = fanout(assign_spatial(boxes, w, units, 0), boxes);
    CHECK(tight <= balanced);
    // Every locality in between keeps most spheres in their regions.
    for (double f : {0.25, 0.5, 0.75}) CHECK(fanout(assign_spatial(boxes, w, units, f), boxes) <= balanced);
  }
}

TEST_CASE("spatial: a partition with no empty unit for every subdivision, unit count and locality",
          "[balance][spatial]") {
  const Scene s = room();
  for (int k : {1, 3, 8}) {
    const auto spheres = make_spheres(s, k);
    for (std::size_t requested : {1, 5, 32, 64, 1000})
      for (double f : {0.0, 0.25, 0.5, 1.0}) {
        INFO("k " << k << " units " << requested << " locality " << f);
        const std::size_t units = units_for(spheres.size(), requested);
        const Assignment a = static_assignment("spatial", s, spheres, units, {}, f);
        CHECK(a.is_partition(spheres.size()));
        CHECK(a.units() == units);
        for (const auto& unit : a.unit) CHECK_FALSE(unit.empty());
        CHECK(static_assignment("spatial", s, spheres, units, {}, f).unit == a.unit);  // deterministic
      }
  }
  // One sphere, one unit.
  Scene one;
  one.objects.push_back({"cube", 0, box(Vec3d(1), 1), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr});
  const auto single = make_spheres(one, 1);
  CHECK(static_assignment("spatial", one, single, units_for(single.size(), 32)).unit == std::vector<Ids>{{0}});
}

TEST_CASE("spatial: spheres without a box have no region and still fill every unit", "[balance][spatial]") {
  // Six cubes, of which 1 and 4 have no bound (hidden): regions of the other four; the two
  // hidden spheres go by load alone.
  auto boxes = cubes_on_a_line(6);
  boxes[1] = boxes[4] = Box<double>{};
  const std::vector<double> w(6, 1);
  CHECK(spatial_regions(boxes, w, 2) == std::vector<Ids>{{0, 2}, {3, 5}});
  for (double f : {0.0, 0.5, 1.0})
    for (std::size_t units : {2, 5, 6}) {
      INFO("locality " << f << " units " << units);
      const Assignment a = assign_spatial(boxes, w, units, f);
      CHECK(a.is_partition(6));
      for (const auto& unit : a.unit) CHECK_FALSE(unit.empty());
    }
  // Bounds leave the hidden ones out.
  const Assignment a = assign_spatial(boxes, w, 2, 1);
  CHECK(partition_quality(a, boxes, w).unit_bound[0].hi.x == 2.5);
}

TEST_CASE("partition quality by hand: fan-out, imbalance and degenerate bounds", "[balance][spatial]") {
  CHECK(load_imbalance({3, 1, 2}) == Approx(1.5));
  CHECK(load_imbalance({0, 0}) == 1);
  CHECK(load_imbalance({}) == 1);
  // Two unit cubes in a box of side 2 (area 24): 6 / 24 each; an empty bound adds nothing.
  const Box<double> scene{{0, 0, 0}, {2, 2, 2}};
  CHECK(expected_fanout({{{0, 0, 0}, {1, 1, 1}}, {{1, 1, 1}, {2, 2, 2}}, {}}, scene) == Approx(0.5));
  // Points: no area anywhere, so every unit with a bound is entered.
  const Box<double> point{{1, 1, 1}, {1, 1, 1}};
  CHECK(expected_fanout({point, point, {}}, point) == 2);
}

TEST_CASE("sphere world boxes follow the objects' matrices", "[balance][spatial]") {
  // A cube of side 2 moving from the origin (frame 0) to (10, 0, 0) (frame 10), turning a
  // quarter about z on the way; K = 2 halves.
  Scene s;
  RigidKey k0, k1;
  k1.frame = 10;
  k1.translate = {10, 0, 0};
  k1.rotate = axis_angle({0, 0, 1}, 90);
  s.objects.push_back({"cube", 0, box(Vec3d(2), 1), std::make_shared<KeyframeMotion>(std::vector<RigidKey>{k0, k1}), nullptr});
  const auto spheres = make_spheres(s, 2);
  REQUIRE(spheres.size() == 2);
  const auto at0 = sphere_world_boxes(s, spheres, 0);
  const auto at10 = sphere_world_boxes(s, spheres, 10);
  Box<double> all0, all10;
  for (int i = 0; i < 2; ++i) all0.extend(at0[i]), all10.extend(at10[i]);
  CHECK(all0.lo == Vec3d(-1, -1, -1));
  CHECK(all0.hi == Vec3d(1, 1, 1));
  CHECK(all10.lo.x == Approx(9));
  CHECK(all10.hi.x == Approx(11));
  for (int i = 0; i < 2; ++i) {
    CHECK(all0.contains(at0[i]));
    CHECK_FALSE(at0[i].empty());
  }
}

TEST_CASE("spatial: when two axes cut to the same area the first axis (x before y) is cut", "[balance][spatial]") {
  // Four unit cubes at the corners of a square in the xy plane (centres (0,0), (2,2), (0,2),
  // (2,0)), equal weights, two regions. Cut along x: {0, 2} and {1, 3}, two boxes 1 x 3 x 1 of
  // area 2 (3 + 3 + 1) = 14 each, 28 in all; along y: {0, 3} and {1, 2}, also 28; along z
  // (every centre at z = 0: the ids' order) {0, 1} and {2, 3}, two diagonal boxes 3 x 3 x 1 of
  // area 30 each, 60. x and y tie; the first axis tried, x, is kept.
  const auto cube = [](double x, double y) { return Box<double>{{x - 0.5, y - 0.5, -0.5}, {x + 0.5, y + 0.5, 0.5}}; };
  const std::vector<Box<double>> boxes = {cube(0, 0), cube(2, 2), cube(0, 2), cube(2, 0)};
  const std::vector<double> equal(4, 1);
  CHECK(spatial_regions(boxes, equal, 2) == std::vector<Ids>{{0, 2}, {1, 3}});
  CHECK(assign_spatial(boxes, equal, 2, 1).unit == std::vector<Ids>{{0, 2}, {1, 3}});
  // Turned a quarter (x <-> y), the same square cuts along the new x: the rule is the axis order.
  const std::vector<Box<double>> turned = {cube(0, 0), cube(2, 2), cube(2, 0), cube(0, 2)};
  CHECK(spatial_regions(turned, equal, 2) == std::vector<Ids>{{0, 3}, {1, 2}});
}

TEST_CASE("spatial: a sphere that widens two units equally stays in its own region's unit", "[balance][spatial]") {
  // A = [0, 10]^3 (centre 5), B = [8, 9]^3 (8.5), C = [20, 21]^3 (20.5), equal weights, two
  // units: the regions are {A} and {B, C} (on every axis the same order; the first cut of the
  // two equally balanced ones). At locality 1 a sphere goes where it widens a unit's bound
  // least: B lies inside both bounds ([0, 10]^3 and [8, 21]^3), a tie that its region's unit,
  // 1, wins, although unit 0 comes first.
  const std::vector<Box<double>> boxes = {{{0, 0, 0}, {10, 10, 10}}, {{8, 8, 8}, {9, 9, 9}}, {{20, 20, 20}, {21, 21, 21}}};
  CHECK(spatial_regions(boxes, {1, 1, 1}, 2) == std::vector<Ids>{{0}, {1, 2}});
  CHECK(assign_spatial(boxes, {1, 1, 1}, 2, 1).unit == std::vector<Ids>{{0}, {1, 2}});
}
