#include "geom/affine.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

namespace {
constexpr double kHalfPi = 1.57079632679489661923;
Affine<double> random_affine(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-2, 2);
  Affine<double> a;
  for (auto& row : a.m)
    for (double& x : row) x = u(rng);
  return a;
}
}  // namespace

TEST_CASE("affine: T R S applied to a point - by hand", "[affine]") {
  // Scale 2, then 90 degrees about z, then translate (1, 2, 3): (1, 0, 0) -> (2, 0, 0) ->
  // (0, 2, 0) -> (1, 4, 3).
  const Affine<double> m = translate({1, 2, 3}) * rotate({0, 0, 1}, kHalfPi) * scale(Vec3d(2));
  const Vec3d p = m.point({1, 0, 0});
  CHECK(p.x == Approx(1).margin(1e-15));
  CHECK(p.y == Approx(4));
  CHECK(p.z == Approx(3));
  const Vec3d v = m.vector({1, 0, 0});  // directions ignore the translation
  CHECK(v.x == Approx(0).margin(1e-15));
  CHECK(v.y == Approx(2));
}

TEST_CASE("affine: inverse undoes the map (seeded random matrices)", "[affine]") {
  std::mt19937_64 rng(7);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Affine<double> a = random_affine(rng);
    auto inv = inverse(a);
    if (!inv) continue;  // the rare nearly-singular draw is rejected, not inverted badly
    ++checked;
    const Affine<double> id = *inv * a;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) CHECK(id.m[r][c] == Approx(r == c ? 1.0 : 0.0).margin(1e-9));
  }
  CHECK(checked > 190);
}

TEST_CASE("affine: singular - NaN and infinite matrices are rejected with a reason", "[affine]") {
  Affine<double> flat = scale({1, 1, 0});
  CHECK_FALSE(inverse(flat));
  CHECK(why_not_invertible(flat).find("singular") != std::string::npos);
  Affine<double> nan;
  nan.m[1][2] = std::nan("");
  CHECK_FALSE(inverse(nan));
  CHECK(why_not_invertible(nan).find("NaN") != std::string::npos);
  Affine<double> inf;
  inf.m[0][3] = kInf<double>;
  CHECK_FALSE(inverse(inf));
  // Two columns almost parallel: nearly singular.
  Affine<double> sheared;
  sheared.m[0][1] = 1;
  sheared.m[1][1] = 1e-12;
  CHECK_FALSE(inverse(sheared));
}

TEST_CASE("affine: tiny and huge but well-shaped maps are valid", "[affine]") {
  for (double s : {1e-4, 1e-2, 1e2, 1e4}) {
    const Affine<double> a = rotate({1, 2, 3}, 0.7) * scale(Vec3d(s));
    auto inv = inverse(a);
    REQUIRE(inv);
    const Vec3d p = inv->point(a.point({0.3, -0.2, 0.9}));
    CHECK(p.x == Approx(0.3));
    CHECK(p.y == Approx(-0.2));
    CHECK(p.z == Approx(0.9));
  }
}

TEST_CASE("affine: max stretch is the largest singular value", "[affine]") {
  CHECK(max_stretch(scale({1, 2, 3})) == Approx(3).epsilon(1e-8));
  CHECK(max_stretch(scale({1, 2, 3})) >= 3);
  CHECK(max_stretch(rotate({1, 1, 0}, 0.4) * scale(Vec3d(2))) == Approx(2).epsilon(1e-8));
  // A shear [[1, 1], [0, 1]] stretches by the golden ratio.
  Affine<double> shear;
  shear.m[0][1] = 1;
  CHECK(max_stretch(shear) == Approx((1 + std::sqrt(5.0)) / 2).epsilon(1e-8));
  // Never below the stretch of any direction (seeded random matrices and directions).
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n;
  for (int i = 0; i < 100; ++i) {
    const Affine<double> a = random_affine(rng);
    const double s = max_stretch(a);
    for (int k = 0; k < 50; ++k) {
      const Vec3d d = glm::normalize(Vec3d(n(rng), n(rng), n(rng)));
      CHECK(glm::length(a.vector(d)) <= s);
    }
  }
}

TEST_CASE("affine: a ray carried to the local frame keeps its parameter", "[affine]") {
  const Affine<double> to_world = translate({5, -1, 2}) * rotate({0, 1, 1}, 1.1) * scale(Vec3d(3));
  const Affine<double> to_local = *inverse(to_world);
  const Ray<double> world{{0, 0, 0}, glm::normalize(Vec3d(1, 2, 3)), 100};
  const Ray<double> local = to_local.ray(world);
  for (double t : {0.5, 2.0, 7.25}) {
    const Vec3d a = to_local.point(world.o + t * world.d);
    const Vec3d b = local.o + t * local.d;
    CHECK(a.x == Approx(b.x));
    CHECK(a.y == Approx(b.y));
    CHECK(a.z == Approx(b.z));
  }
  // The local direction is not unit: scale 3 shrinks it to 1/3.
  CHECK(glm::length(local.d) == Approx(1.0 / 3));
  CHECK(local.tmax == 100);
}
