#include "geom/triangle_soa.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
template <typename T>
MollerTriangle<T> unit_tri() {  // (0,0,5) (1,0,5) (0,1,5): e1 = x, e2 = y
  return prepare_moller<T>({0, 0, 5}, {1, 0, 5}, {0, 1, 5});
}
template <typename T>
Ray<T> down_z(T x, T y, T tmax = kInf<T>) {
  return {{x, y, 0}, {0, 0, 1}, tmax};
}
}  // namespace

TEMPLATE_TEST_CASE("moller: a hit with hand-computed t - u - v", "[triangle]", float, double) {
  using T = TestType;
  const auto h = intersect_moller(down_z<T>(0.25, 0.5), unit_tri<T>());
  CHECK(h.hit);
  CHECK(h.stage == TriStage::t);
  CHECK(h.t == T(5));
  CHECK(h.u == T(0.25));  // along e1
  CHECK(h.v == T(0.5));   // along e2
}

TEMPLATE_TEST_CASE("moller: each exit stage by hand", "[triangle]", float, double) {
  using T = TestType;
  const auto tri = unit_tri<T>();
  // Parallel to the plane: det = 0.
  auto h = intersect_moller(Ray<T>{{0, 0, 5}, {1, 0, 0}, kInf<T>}, tri);
  CHECK(h.stage == TriStage::det);
  CHECK_FALSE(h.hit);
  // u < 0 and u > 1.
  CHECK(intersect_moller(down_z<T>(-0.5, 0.25), tri).stage == TriStage::u);
  CHECK(intersect_moller(down_z<T>(1.5, 0.25), tri).stage == TriStage::u);
  // v < 0, and u + v > 1.
  CHECK(intersect_moller(down_z<T>(0.25, -0.5), tri).stage == TriStage::v);
  CHECK(intersect_moller(down_z<T>(0.75, 0.75), tri).stage == TriStage::v);
  // Inside the triangle but behind the origin, or beyond tmax: rejected at the last stage.
  h = intersect_moller(Ray<T>{{0.25, 0.25, 10}, {0, 0, 1}, kInf<T>}, tri);
  CHECK(h.stage == TriStage::t);
  CHECK_FALSE(h.hit);
  h = intersect_moller(down_z<T>(0.25, 0.25, 4), tri);
  CHECK(h.stage == TriStage::t);
  CHECK_FALSE(h.hit);
  // Back side: the same hit from the other direction.
  h = intersect_moller(Ray<T>{{0.25, 0.25, 10}, {0, 0, -1}, kInf<T>}, tri);
  CHECK(h.hit);
  CHECK(h.t == T(5));
}

TEMPLATE_TEST_CASE("moller: a degenerate triangle is never hit", "[triangle][hard]", float, double) {
  using T = TestType;
  const auto line = prepare_moller<T>({0, 0, 5}, {1, 1, 5}, {2, 2, 5});   // collinear
  const auto point = prepare_moller<T>({1, 1, 5}, {1, 1, 5}, {1, 1, 5});  // one point
  for (const auto& tri : {line, point}) {
    CHECK(tri.n == Vec3<T>(0));
    for (T x : {T(0), T(0.5), T(1), T(1.5)}) {
      const auto h = intersect_moller(down_z<T>(x, x), tri);
      CHECK_FALSE(h.hit);
      CHECK(h.stage == TriStage::det);
    }
  }
}

TEMPLATE_TEST_CASE("moller: rays with zero direction components", "[triangle]", float, double) {
  using T = TestType;
  // Axis-aligned ray into a triangle in the x = 3 plane.
  const auto tri = prepare_moller<T>({3, 0, 0}, {3, 1, 0}, {3, 0, 1});
  const auto h = intersect_moller(Ray<T>{{0, 0.25, 0.25}, {1, 0, 0}, kInf<T>}, tri);
  CHECK(h.hit);
  CHECK(h.t == T(3));
}

TEMPLATE_TEST_CASE("block kernels: nearest and any over a small soup", "[triangle]", float, double) {
  using T = TestType;
  TriangleStore<T> soa(Kernel::moller);
  soa.push_back({0, 0, 7}, {1, 0, 7}, {0, 1, 7});    // 0: t = 7
  soa.push_back({5, 5, 1}, {6, 5, 1}, {5, 6, 1});    // 1: missed (u)
  soa.push_back({0, 0, 3}, {1, 0, 3}, {0, 1, 3});    // 2: t = 3, nearest
  soa.push_back({0, 0, 3}, {1, 0, 3}, {0, 1, 3});    // 3: t = 3 again: tie
  std::uint64_t stages[kTriStages] = {}, hits = 0;
  const auto ray = down_z<T>(0.25, 0.25);
  const BlockHit<T> b = nearest_in_block(soa, 0, 4, ray, stages, &hits);
  CHECK(b.index == 2);  // the lower index wins the tie
  CHECK(b.t == T(3));
  CHECK(hits == 3);
  CHECK(stages[int(TriStage::t)] == 3);
  CHECK(stages[int(TriStage::u)] == 1);
  std::uint64_t s2[kTriStages] = {}, h2 = 0;
  CHECK(any_in_block(soa, 0, 4, ray, s2, &h2));
  CHECK(h2 == 1);
  CHECK(s2[int(TriStage::t)] == 1);  // stopped at the first occluder
}
