#include "scene/generate.h"

#include <catch2/catch.hpp>

using namespace oprt;

TEST_CASE("generators: triangle counts follow their formulas", "[generate]") {
  CHECK(triangle_cloud(2048, 1, 0.1, 1).triangles.size() == 2048);
  CHECK(box({1, 2, 3}, 1).triangles.size() == 12);
  CHECK(box({1, 2, 3}, 4).triangles.size() == 6 * 2 * 16);
  CHECK(uv_sphere(1, 16, 8).triangles.size() == 2 * 16 * 7);
  CHECK(cylinder(1, 2, 20, true).triangles.size() == 2 * 20 + 2 * 20);
  CHECK(cylinder(1, 2, 20, false).triangles.size() == 40);
  CHECK(torus(1, 0.2, 24, 12).triangles.size() == 2 * 24 * 12);
  CHECK(plane(4, 4, 3, 5).triangles.size() == 2 * 15);
}

TEST_CASE("generators: geometry stays in its stated bounds", "[generate]") {
  const Mesh cloud = triangle_cloud(500, 2, 0.3, 42);
  for (const Vec3d& v : cloud.vertices) CHECK(glm::length(v) <= 2 + 1e-12);
  const Mesh s = uv_sphere(1.5, 12, 6);
  for (const Vec3d& v : s.vertices) CHECK(glm::length(v) == Approx(1.5));
  const Mesh b = box({2, 4, 6}, 2);
  for (const Vec3d& v : b.vertices) {
    CHECK(std::fabs(v.x) <= 1);
    CHECK(std::fabs(v.y) <= 2);
    CHECK(std::fabs(v.z) <= 3);
  }
}

TEST_CASE("generators: a seeded cloud is the same every time; another seed differs", "[generate]") {
  const Mesh a = triangle_cloud(64, 1, 0.1, 9), b = triangle_cloud(64, 1, 0.1, 9), c = triangle_cloud(64, 1, 0.1, 10);
  CHECK(a.vertices == b.vertices);
  CHECK(a.vertices != c.vertices);
}
