#include "geom/triangle_soa.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace oprt;

namespace {
template <typename T>
WatertightRay<T> down_z(T x, T y, T tmax = kInf<T>) {
  return watertight_ray(Ray<T>{{x, y, 0}, {0, 0, 1}, tmax});
}
template <typename T>
WatertightTriangle<T> unit_tri() {  // (0,0,5) (1,0,5) (0,1,5)
  return prepare_watertight<T>({0, 0, 5}, {1, 0, 5}, {0, 1, 5});
}
}  // namespace

TEMPLATE_TEST_CASE("watertight: a hit with hand-computed t - u - v", "[watertight]", float, double) {
  using T = TestType;
  // From (0.25, 0.5, 0) along +z: U = 0.25, V = 0.25, W = 0.5, det = 1, T = 5, D = 1.
  const auto h = intersect_watertight(down_z<T>(0.25, 0.5), unit_tri<T>());
  CHECK(h.hit);
  CHECK(h.stage == WtStage::t);
  CHECK(h.t == T(5));
  CHECK(h.u == T(0.25));  // weight of v1
  CHECK(h.v == T(0.5));   // weight of v2
}

TEMPLATE_TEST_CASE("watertight: each exit stage by hand", "[watertight]", float, double) {
  using T = TestType;
  const auto tri = unit_tri<T>();
  CHECK(intersect_watertight(down_z<T>(-0.5, 0.25), tri).stage == WtStage::uv);  // U = 1.25, V = -0.5
  CHECK(intersect_watertight(down_z<T>(0.75, 0.75), tri).stage == WtStage::uv);  // U = -0.5, V = 0.75
  CHECK(intersect_watertight(down_z<T>(0.25, -0.5), tri).stage == WtStage::w);   // U, V > 0, W = -0.5
  // In the triangle's plane: the projected vertices and the origin are collinear, all zero.
  auto h = intersect_watertight(watertight_ray(Ray<T>{{0, 0, 5}, {1, 0, 0}, kInf<T>}), tri);
  CHECK(h.stage == WtStage::det);
  CHECK_FALSE(h.hit);
  // Behind the origin, or beyond tmax: rejected at the last stage.
  h = intersect_watertight(watertight_ray(Ray<T>{{0.25, 0.25, 10}, {0, 0, 1}, kInf<T>}), tri);
  CHECK(h.stage == WtStage::t);
  CHECK_FALSE(h.hit);
  h = intersect_watertight(down_z<T>(0.25, 0.25, 4), tri);
  CHECK(h.stage == WtStage::t);
  CHECK_FALSE(h.hit);
  // The back side gives the same hit.
  h = intersect_watertight(watertight_ray(Ray<T>{{0.25, 0.25, 10}, {0, 0, -1}, kInf<T>}), tri);
  CHECK(h.hit);
  CHECK(h.t == T(5));
}

TEMPLATE_TEST_CASE("watertight: the dominant axis - ties to the lower axis", "[watertight]", float, double) {
  using T = TestType;
  CHECK(watertight_ray(Ray<T>{{0, 0, 0}, {0, 0, 1}, kInf<T>}).kz == 2);
  CHECK(watertight_ray(Ray<T>{{0, 0, 0}, {0, -1, 0.5}, kInf<T>}).kz == 1);
  CHECK(watertight_ray(Ray<T>{{0, 0, 0}, {1, -1, 1}, kInf<T>}).kz == 0);
  const auto r = watertight_ray(Ray<T>{{0, 0, 0}, {0.5, 0.25, -1}, kInf<T>});
  CHECK((r.kx == 0 && r.ky == 1 && r.kz == 2));
  CHECK((r.dx == T(0.5) && r.dy == T(0.25) && r.dz == T(-1)));
}

TEMPLATE_TEST_CASE("watertight: a degenerate triangle is never hit and exits at det", "[watertight][hard]", float,
                   double) {
  using T = TestType;
  const auto line = prepare_watertight<T>({0, 0, 5}, {1, 1, 5}, {2, 2, 5});
  const auto point = prepare_watertight<T>({1, 1, 5}, {1, 1, 5}, {1, 1, 5});
  CHECK((line.v1 == line.v0 && line.v2 == line.v0));  // stored collapsed
  for (const auto& tri : {line, point})
    for (T x : {T(0), T(0.5), T(1), T(1.5)})
      for (const Ray<T>& r : {Ray<T>{{x, x, 0}, {0, 0, 1}, kInf<T>}, Ray<T>{{x, x, 0}, {0.6f, 0, 0.8f}, kInf<T>}}) {
        const auto h = intersect_watertight(watertight_ray(r), tri);
        CHECK_FALSE(h.hit);
        CHECK(h.stage == WtStage::det);
      }
}

TEMPLATE_TEST_CASE("watertight: rays with zero direction components", "[watertight]", float, double) {
  using T = TestType;
  const auto tri = prepare_watertight<T>({3, 0, 0}, {3, 1, 0}, {3, 0, 1});
  const auto h = intersect_watertight(watertight_ray(Ray<T>{{0, 0.25, 0.25}, {1, 0, 0}, kInf<T>}), tri);
  CHECK(h.hit);
  CHECK(h.t == T(3));
}

TEST_CASE("watertight: edge functions that round to zero get their exact sign", "[watertight][hard]") {
  // float: (1 + 2^-12)^2 = 1 + 2^-11 + 2^-24 rounds to 1 + 2^-11 (a tie, to even), so
  // a b - c d rounds to 0 with a = b = 1 + 2^-12, c = 1 + 2^-11, d = 1; exactly it is 2^-24.
  const float af = 1 + std::ldexp(1.0f, -12), cf = 1 + std::ldexp(1.0f, -11);
  CHECK(af * af - cf * 1.0f == 0.0f);
  int s = 0;
  CHECK(detail::edge(af, af, cf, 1.0f, &s) == std::ldexp(1.0f, -24));
  CHECK(s == 1);
  CHECK(detail::edge(cf, 1.0f, af, af, &s) == -std::ldexp(1.0f, -24));
  CHECK(s == -1);
  // double: (1 + 2^-27)^2 = 1 + 2^-26 + 2^-54 rounds to 1 + 2^-26; exactly 2^-54 remains.
  const double ad = 1 + std::ldexp(1.0, -27), cd = 1 + std::ldexp(1.0, -26);
  CHECK(ad * ad - cd * 1.0 == 0.0);
  CHECK(detail::edge(ad, ad, cd, 1.0, &s) == std::ldexp(1.0, -54));
  CHECK(s == 1);
  CHECK(detail::edge(cd, 1.0, ad, ad, &s) == -std::ldexp(1.0, -54));
  CHECK(s == -1);
  // A true zero stays zero.
  CHECK(detail::edge(ad, cd, cd, ad, &s) == 0.0);
  CHECK(s == 0);
}

TEMPLATE_TEST_CASE("watertight: a point exactly on a shared edge is owned by one triangle", "[watertight][hard]",
                   float, double) {
  using T = TestType;
  // The square [0,1]^2 at z = 5 split along its diagonal, in both windings and from both sides.
  const Vec3d a{0, 0, 5}, b{1, 0, 5}, c{1, 1, 5}, d{0, 1, 5};
  for (bool flip : {false, true})
    for (double dz : {1.0, -1.0}) {
      const auto t1 = flip ? prepare_watertight<T>(a, c, b) : prepare_watertight<T>(a, b, c);
      const auto t2 = prepare_watertight<T>(a, c, d);
      for (int k = 1; k < 8; ++k) {
        const T x = T(k) / 8;
        const auto r = watertight_ray(Ray<T>{{x, x, T(5 - 5 * dz)}, {0, 0, T(dz)}, kInf<T>});
        const int hits = intersect_watertight(r, t1).hit + intersect_watertight(r, t2).hit;
        INFO("flip " << flip << " dz " << dz << " x " << x);
        CHECK(hits == 1);
      }
    }
}

TEMPLATE_TEST_CASE("watertight: a point exactly on a vertex shared by a fan is owned by one triangle",
                   "[watertight][hard]", float, double) {
  using T = TestType;
  // Twelve triangles around (0.5, 0.25, 2), windings alternating; rays through the centre
  // from several directions.
  const Vec3d centre{0.5, 0.25, 2};
  Vec3d rim[12];  // each rim vertex computed once: neighbours must share it bit for bit
  for (int i = 0; i < 12; ++i) {
    const double a = 2 * 3.141592653589793 * i / 12;
    rim[i] = {0.5 + std::cos(a), 0.25 + std::sin(a), 2};
  }
  std::vector<WatertightTriangle<T>> fan;
  for (int i = 0; i < 12; ++i) {
    const Vec3d &p = rim[i], &q = rim[(i + 1) % 12];
    fan.push_back(i % 2 ? prepare_watertight<T>(centre, p, q) : prepare_watertight<T>(q, centre, p));
  }
  for (const Vec3d& dir : {Vec3d(0, 0, 1), Vec3d(0, 0, -1), Vec3d(0.25, -0.5, 1), Vec3d(-0.5, 0.5, -1)}) {
    const Vec3d o = centre - dir * 3.0;  // exact in both precisions
    const auto r = watertight_ray(Ray<T>{Vec3<T>(o), Vec3<T>(dir), kInf<T>});
    int hits = 0;
    for (const auto& t : fan) hits += intersect_watertight(r, t).hit;
    INFO("direction " << dir.x << " " << dir.y << " " << dir.z);
    CHECK(hits == 1);
  }
}

TEMPLATE_TEST_CASE("block kernels: the watertight store dispatches to its kernel", "[watertight]", float, double) {
  using T = TestType;
  TriangleStore<T> soa(Kernel::watertight);
  soa.push_back({0, 0, 7}, {1, 0, 7}, {0, 1, 7});  // 0: t = 7
  soa.push_back({5, 5, 1}, {6, 5, 1}, {5, 6, 1});  // 1: missed
  soa.push_back({0, 0, 3}, {1, 0, 3}, {0, 1, 3});  // 2: t = 3, nearest
  soa.push_back({0, 0, 3}, {1, 0, 3}, {0, 1, 3});  // 3: t = 3 again: tie
  soa.push_back({0, 0, 2}, {1, 1, 2}, {2, 2, 2});  // 4: degenerate
  CHECK(soa.size() == 5);
  CHECK(soa.bytes_per_triangle() == 9 * sizeof(T));
  CHECK(TriangleStore<T>(Kernel::moller).bytes_per_triangle() == 12 * sizeof(T));
  std::uint64_t stages[kTriStages] = {}, hits = 0;
  const Ray<T> ray{{0.25, 0.25, 0}, {0, 0, 1}, kInf<T>};
  const BlockHit<T> b = nearest_in_block(soa, 0, 5, ray, stages, &hits);
  CHECK(b.index == 2);
  CHECK(b.t == T(3));
  CHECK(hits == 3);
  CHECK(stages[int(WtStage::t)] == 3);
  CHECK(stages[int(WtStage::uv)] + stages[int(WtStage::w)] == 1);
  CHECK(stages[int(WtStage::det)] == 1);
  std::uint64_t s2[kTriStages] = {}, h2 = 0;
  CHECK(any_in_block(soa, 0, 5, ray, s2, &h2));
  CHECK(h2 == 1);
  CHECK(s2[int(WtStage::t)] == 1);
}
