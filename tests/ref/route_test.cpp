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
