#include "geom/sphere.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;

TEMPLATE_TEST_CASE("sphere: hits and misses by hand", "[sphere]", float, double) {
  using T = TestType;
  const Ray<T> ray{{0, 0, 0}, {0, 0, 1}, kInf<T>};
  CHECK(hit_sphere(ray, Sphere<T>{{0, 0, 5}, 1}));           // straight ahead
  CHECK(hit_sphere(ray, Sphere<T>{{0, T(0.99), 5}, 1}));     // grazes inside
  CHECK_FALSE(hit_sphere(ray, Sphere<T>{{0, T(1.01), 5}, 1}));  // passes just outside
  CHECK_FALSE(hit_sphere(ray, Sphere<T>{{0, 0, -5}, 1}));    // behind the origin
  CHECK(hit_sphere(ray, Sphere<T>{{0, 0, -0.5}, 1}));        // origin inside, centre behind
  CHECK(hit_sphere(ray, Sphere<T>{{3, 0, 0}, 5}));           // origin inside, centre to the side
}

TEST_CASE("sphere: a tiny sphere far away is not missed in float (stable form)", "[sphere][hard]") {
  // Rays from near the origin aimed at the centre of a sphere of radius 1e-2 at distance
  // 1e4 in random directions. The stable form must hit every one; the textbook form
  // |f|^2 - (f.d)^2 cancels catastrophically here, and its misses are counted to show why.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n;
  int stable_misses = 0, textbook_misses = 0;
  const int trials = 2000;
  for (int i = 0; i < trials; ++i) {
    const Vec3d dir = glm::normalize(Vec3d(n(rng), n(rng), n(rng)));
    const Vec3d o(n(rng) * 0.1, n(rng) * 0.1, n(rng) * 0.1);
    const Vec3d c = o + dir * 1e4;
    const Ray<float> ray{Vec3f(o), Vec3f(glm::normalize(c - Vec3d(Vec3f(o)))), kInf<float>};
    const Sphere<float> s{Vec3f(c), 1e-2f};
    stable_misses += !hit_sphere(ray, s);
    textbook_misses += !hit_sphere_textbook(ray, s);
  }
  INFO("textbook misses: " << textbook_misses << " of " << trials);
  CHECK(stable_misses == 0);
  CHECK(textbook_misses > trials / 10);  // the hard case is real
}
