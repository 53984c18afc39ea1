#include "geom/bounding_sphere.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

TEST_CASE("minimal sphere: known answers", "[bounding]") {
  // Cube corners: centre of the cube, half the space diagonal.
  std::vector<Vec3d> cube;
  for (int i = 0; i < 8; ++i) cube.push_back({i & 1 ? 3.0 : 1.0, i & 2 ? 2.0 : 0.0, i & 4 ? 5.0 : 3.0});
  auto s = minimal_sphere(cube);
  CHECK(s.c.x == Approx(2));
  CHECK(s.c.y == Approx(1));
  CHECK(s.c.z == Approx(4));
  CHECK(s.r == Approx(std::sqrt(3.0)));
  // An obtuse triangle: the ball spans its longest side, not its circumcircle.
  s = minimal_sphere({{-1, 0, 0}, {1, 0, 0}, {0, 0.1, 0}});
  CHECK(s.c.x == Approx(0).margin(1e-12));
  CHECK(s.r == Approx(1));
  // Regular tetrahedron with edge sqrt(8): circumradius sqrt(3).
  s = minimal_sphere({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}});
  CHECK(s.r == Approx(std::sqrt(3.0)));
  // One point.
  s = minimal_sphere({{4, 5, 6}});
  CHECK(s.r == 0);
}

TEST_CASE("minimal sphere: encloses - and no nearby centre does better (seeded clouds)", "[bounding]") {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3d> pts;
    const int count = 50 + trial * 100;
    for (int i = 0; i < count; ++i) pts.push_back({n(rng) * 3, n(rng), n(rng) * 0.5 + trial});
    const auto s = minimal_sphere(pts);
    CHECK(enclosing_radius(pts, s.c) <= s.r);
    // Optimality: moving the centre a little in any direction never shrinks the radius.
    for (int k = 0; k < 64; ++k) {
      const Vec3d d = glm::normalize(Vec3d(n(rng), n(rng), n(rng))) * (s.r * 1e-4);
      CHECK(enclosing_radius(pts, s.c + d) >= s.r * (1 - 1e-12));
    }
    CHECK(s.r <= ritter_sphere(pts).r * (1 + 1e-12));
  }
}
