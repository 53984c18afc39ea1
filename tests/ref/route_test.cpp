// The router's decisions on boxes placed by hand (ref/route.h): which units a ray enters,
// at what distance, in which order, and when the closest hit so far makes a unit useless.
#include "ref/frame_trace.h"
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

namespace {
// Counts what route_ray (ref/frame_trace.h) tells the recorder: the units visited, in order,
// the waves and the skipped units.
struct WaveCounter {
  std::vector<std::uint32_t> visited, skipped;
  std::vector<std::size_t> wave_sizes;  // units visited per wave
  std::size_t in_wave = 0;
  void wave_end() {
    wave_sizes.push_back(in_wave);
    in_wave = 0;
  }
  void skip(std::uint32_t u) { skipped.push_back(u); }
};

// Five units, boxes x in [2k, 2k + 1] for k = 1..5, all on the ray's line: entered at 2, 4,
// 6, 8 and 10, in unit order. `hit_in` (a unit, its hit's t): the closest hit once that unit
// has answered. `occluder`: a shadow ray's unit that answers "occluded".
WaveCounter route_five(std::uint32_t wave, std::uint32_t hit_in = 99, float hit_t = 0, std::uint32_t occluder = 99) {
  RouteTable<float> t;
  t.route = Route::ordered;
  t.wave = wave;
  for (int k = 1; k <= 5; ++k) t.bound.push_back(slab_x(2.0f * k, 2.0f * k + 1));
  const SceneGeometry<float> g;
  const std::vector<IuRegisters<float>> units(5);
  const CameraRays camera(Camera{}, 1, 1);
  const Scene scene;
  const FrameSetup<float> setup;
  const Shader<float> shader(scene, setup);
  const FrameTraceInputs<float> in{g, units, camera, shader, false, &t};
  PixelScratch<float> scratch;
  WaveCounter rec;
  float limit = kInf<float>;
  route_ray(
      in, along_x, 0, rec, scratch,
      [&](std::uint32_t u) {
        rec.visited.push_back(u);
        ++rec.in_wave;
        if (u == hit_in) limit = hit_t;
        return u == occluder;
      },
      [&] { return limit; });
  return rec;
}
}  // namespace

TEST_CASE("route: ordered routing sends a ray in waves of `wave` units, nearest first", "[ref][route]") {
  using Sizes = std::vector<std::size_t>;
  using Units = std::vector<std::uint32_t>;
  // Nothing hit: all five units, in waves of 1, 2, 3, 5 and 8 units: 5, 3, 2, 1 and 1 waves.
  for (const auto& [wave, sizes] : {std::pair<std::uint32_t, Sizes>{1, {1, 1, 1, 1, 1}}, {2, {2, 2, 1}}, {3, {3, 2}},
                                    {5, {5}}, {8, {5}}}) {
    INFO("wave " << wave);
    const WaveCounter r = route_five(wave);
    CHECK(r.wave_sizes == sizes);
    CHECK(r.visited == Units{0, 1, 2, 3, 4});
    CHECK(r.skipped.empty());
  }
  // A hit at t = 4.5 in unit 1 (entered at 4): after the first wave of two, units 2, 3 and 4
  // are entered beyond it (at 6, 8, 10) and skipped; one wave in all.
  WaveCounter r = route_five(2, 1, 4.5f);
  CHECK(r.wave_sizes == Sizes{2});
  CHECK(r.visited == Units{0, 1});
  CHECK(r.skipped == Units{2, 3, 4});
  // In waves of one the hit in unit 1 is known before unit 2: again two units visited, two waves.
  r = route_five(1, 1, 4.5f);
  CHECK(r.wave_sizes == Sizes{1, 1});
  CHECK(r.skipped == Units{2, 3, 4});
  // A hit at 8 (unit 3's entry, in unit 1): units 2 and 3 are still worth a visit (a unit entered
  // at the hit may hold an equal t), unit 4 is not; the skipped unit does not count in a wave.
  r = route_five(2, 1, 8.0f);
  CHECK(r.wave_sizes == Sizes{2, 2});
  CHECK(r.visited == Units{0, 1, 2, 3});
  CHECK(r.skipped == Units{4});
  // The hit is known only when its wave is over: in one wave of three the third unit is
  // visited although the hit in the second lies before it.
  r = route_five(3, 1, 4.5f);
  CHECK(r.wave_sizes == Sizes{3});
  CHECK(r.skipped == Units{3, 4});
  // A shadow ray occluded in unit 0 stops after its wave: unit 1 (same wave) is still asked,
  // the rest are skipped.
  r = route_five(2, 99, 0, 0);
  CHECK(r.wave_sizes == Sizes{2});
  CHECK(r.visited == Units{0, 1});
  CHECK(r.skipped == Units{2, 3, 4});
  // Occluded in the last wave's first unit: its second unit is still asked, nothing is skipped.
  r = route_five(3, 99, 0, 3);
  CHECK(r.wave_sizes == Sizes{3, 2});
  CHECK(r.skipped.empty());
}
