// The router's decisions on boxes placed by hand (ref/route.h): which units a ray enters,
// at what distance, in which order, and when the closest hit so far makes a unit useless.
#include "ref/route.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
Box<float> slab_x(float lo, float hi) {  // a unit cube's y, z extent, x from lo to hi
  Box<float> b;
  b.lo = {lo, 0, 0};
  b.hi = {hi, 1, 1};
  return b;
}

RouteTable<float> three_units(Route route) {
  RouteTable<float> t;
  t.route = route;
  Box<float> off;  // beside the ray's line: y from 10 to 11
  off.lo = {0, 10, 0};
  off.hi = {1, 11, 1};
  t.bound = {slab_x(5, 6), slab_x(2, 3), off, Box<float>{}};  // unit 3 shows nothing this frame
  return t;
}

std::vector<std::uint32_t> units_of(const std::vector<RouteTable<float>::Entered>& e) {
  std::vector<std::uint32_t> u;
  for (const auto& x : e) u.push_back(x.unit);
  return u;
}

const Ray<float> along_x{{0, 0.5f, 0.5f}, {1, 0, 0}};
}  // namespace

TEST_CASE("route: multicast addresses the units whose bound the ray enters, in unit order", "[ref][route]") {
  const auto t = three_units(Route::multicast);
  std::vector<RouteTable<float>::Entered> e;
  REQUIRE(t.entered(along_x, e) == 2);
  CHECK(units_of(e) == std::vector<std::uint32_t>{0, 1});
  CHECK(e[0].entry == 5.0f);  // (5 - 0) * (1 / 1): exact
  CHECK(e[1].entry == 2.0f);
}

TEST_CASE("route: ordered sorts by entry distance and a ray's end cuts the list", "[ref][route]") {
  auto t = three_units(Route::ordered);
  std::vector<RouteTable<float>::Entered> e;
  REQUIRE(t.entered(along_x, e) == 2);
  CHECK(units_of(e) == std::vector<std::uint32_t>{1, 0});
  Ray<float> shadow = along_x;
  shadow.tmax = 4;  // the light before unit 0's box
  REQUIRE(t.entered(shadow, e) == 1);
  CHECK(e[0].unit == 1);
  // Ties in distance go to the lower unit.
  t.bound[0] = slab_x(2, 4);
  REQUIRE(t.entered(along_x, e) == 2);
  CHECK(units_of(e) == std::vector<std::uint32_t>{0, 1});
}

TEST_CASE("route: a unit entered beyond the closest hit is not worth a visit", "[ref][route]") {
  const auto t = three_units(Route::ordered);
  CHECK_FALSE(t.worth(along_x, 0, 4.0f));  // a hit at 4: unit 0's box begins at 5
  CHECK(t.worth(along_x, 0, 5.5f));
  CHECK(t.worth(along_x, 1, 2.0f));  // entered exactly at the hit: it may hold an equal t
}

TEST_CASE("route: a ray that starts inside a bound enters it at 0", "[ref][route]") {
  const auto t = three_units(Route::ordered);
  std::vector<RouteTable<float>::Entered> e;
  const Ray<float> inside{{2.5f, 0.5f, 0.5f}, {1, 0, 0}};
  REQUIRE(t.entered(inside, e) == 2);
  CHECK(e[0].unit == 1);
  CHECK(e[0].entry == 0.0f);
}

TEST_CASE("route: per-sphere bounds let a ray pass between a unit's distant spheres", "[ref][route]") {
  RouteTable<float> t;
  t.route = Route::multicast;
  // Unit 0 holds two spheres, x in [0, 1] and [9, 10]; their union spans x in [0, 10].
  t.bound = {slab_x(0, 10)};
  t.per_sphere = true;
  t.first = {0, 2};
  t.boxes = {slab_x(0, 1), slab_x(9, 10)};
  CHECK(t.tested() == 2);
  std::vector<RouteTable<float>::Entered> e;
  const Ray<float> between{{5, 0.5f, -1}, {0, 0, 1}};  // crosses z at x = 5: inside the union only
  CHECK(t.entered(between, e) == 0);
  CHECK_FALSE(t.worth(between, 0, kInf<float>));
  const Ray<float> through_far{{-1, 0.5f, 0.5f}, {1, 0, 0}};  // enters the near box at 1, the far at 10
  REQUIRE(t.entered(through_far, e) == 1);
  CHECK(e[0].entry == 1.0f);  // the nearer of its spheres' entries
  t.per_sphere = false;  // one box per unit: the ray between them enters it
  CHECK(t.tested() == 1);
  CHECK(t.entered(between, e) == 1);
}

// Replicated spheres (--replicate): a sphere's own box, outside its units' bounds; a ray
// that enters it goes to the one copy whose share its key is (copy key mod copies, the
// copies' units in unit order), merged with the units it enters anyway.
TEST_CASE("route: a replicated sphere's box addresses exactly one copy, by the ray's key", "[ref][route]") {
  auto t = three_units(Route::multicast);
  t.shared_box = {slab_x(8, 9)};
  t.shared_first = {0, 3};
  t.shared_units = {0, 2, 3};  // copies on units 0, 2 and 3
  CHECK(t.tested() == 5);      // four unit bounds and one box per replicated sphere
  std::vector<RouteTable<float>::Entered> e;
  // Key 0: copy 0 (unit 0), which the ray enters anyway: its entry stays the nearer (5).
  REQUIRE(t.entered(along_x, e, 0) == 2);
  CHECK(units_of(e) == std::vector<std::uint32_t>{0, 1});
  CHECK(e[0].entry == 5.0f);
  // Key 1: copy 1 (unit 2), added in unit order at the sphere's entry; key 4 likewise (4 mod 3).
  for (std::uint32_t key : {1u, 4u}) {
    REQUIRE(t.entered(along_x, e, key) == 3);
    CHECK(units_of(e) == std::vector<std::uint32_t>{0, 1, 2});
    CHECK(e[2].entry == 8.0f);
  }
  // Key 2: copy 2 (unit 3, which shows nothing else this frame).
  REQUIRE(t.entered(along_x, e, 2) == 3);
  CHECK(units_of(e) == std::vector<std::uint32_t>{0, 1, 3});
  // Ordered: by entry distance, and a unit is worth a visit only for its own copy's share.
  t.route = Route::ordered;
  REQUIRE(t.entered(along_x, e, 2) == 3);
  CHECK(units_of(e) == std::vector<std::uint32_t>{1, 0, 3});
  CHECK(t.worth(along_x, 3, 8.5f, 2));
  CHECK_FALSE(t.worth(along_x, 3, 7.5f, 2));  // a hit at 7.5: the copy's box begins at 8
  CHECK_FALSE(t.worth(along_x, 3, 8.5f, 1));  // not unit 3's share
  CHECK(t.worth(along_x, 2, 8.5f, 1));
}
