#include "scene/generate.h"
#include "scene/load.h"

#include <algorithm>

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

TEST_CASE("generators: a seeded cloud is the same every time - another seed differs", "[generate]") {
  const Mesh a = triangle_cloud(64, 1, 0.1, 9), b = triangle_cloud(64, 1, 0.1, 9), c = triangle_cloud(64, 1, 0.1, 10);
  CHECK(a.vertices == b.vertices);
  CHECK(a.vertices != c.vertices);
}

TEST_CASE("generators: a lathe has 2 * segments * (points - 1) triangles plus segments per cap", "[generate]") {
  const std::vector<std::pair<double, double>> vase = {{0.3, 0}, {0.5, 0.4}, {0.2, 0.9}, {0.25, 1}};
  CHECK(lathe(vase, 24, false, false).triangles.size() == 2 * 24 * 3);
  CHECK(lathe(vase, 24, true, false).triangles.size() == 2 * 24 * 3 + 24);
  CHECK(lathe(vase, 24, true, true).triangles.size() == 2 * 24 * 3 + 2 * 24);
  CHECK(lathe({{1, 0}, {1, 2}}, 20, true, true).triangles.size() == cylinder(1, 2, 20, true).triangles.size());
}

TEST_CASE("generators: lathe vertices lie on the profile's circles", "[generate]") {
  const Mesh m = lathe({{0.3, 0}, {0.5, 0.4}, {0.2, 0.9}}, 16, true, true);
  for (const Vec3d& v : m.vertices) {
    const double r = std::hypot(v.x, v.z);
    const bool on_profile = (v.y == 0 && (r == Approx(0.3) || r < 1e-12)) || (v.y == 0.4 && r == Approx(0.5)) ||
                            (v.y == 0.9 && (r == Approx(0.2) || r < 1e-12));
    CHECK(on_profile);
  }
  CHECK(m.vertices.size() == 3 * 16 + 2);
}

TEST_CASE("generators: lathe from JSON with caps - bad profile rejected", "[generate]") {
  const auto doc = JsonIn::parse_text(
      R"({"kind": "lathe", "profile": [[0.5, 0], [0.6, 1], [0.4, 2]], "segments": 10, "cap_first": true})", "t.json");
  CHECK(generate_from_json(JsonIn(doc, "t.json")).triangles.size() == 2 * 10 * 2 + 10);
  const auto one = JsonIn::parse_text(R"({"kind": "lathe", "profile": [[0.5, 0]]})", "t.json");
  CHECK_THROWS_AS(generate_from_json(JsonIn(one, "t.json")), InputError);
  const auto zero_r = JsonIn::parse_text(R"({"kind": "lathe", "profile": [[0, 0], [1, 1]]})", "t.json");
  CHECK_THROWS_AS(generate_from_json(JsonIn(zero_r, "t.json")), InputError);
  const auto extra = JsonIn::parse_text(R"({"kind": "lathe", "profile": [[1, 0], [1, 1]], "caps": true})", "t.json");
  CHECK_THROWS_AS(generate_from_json(JsonIn(extra, "t.json")), InputError);
}

// The paper's two test scenes (Fig. 5), written by scripts/make_paper_scenes.
TEST_CASE("paper scenes: polygons is 32 equal animated groups of 2048 triangles", "[generate][paper]") {
  const Scene s = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_polygons.json");
  CHECK(s.triangle_count() == 65536);
  REQUIRE(s.objects.size() == 32);
  for (const Object& o : s.objects) {
    CHECK(o.mesh.triangles.size() == 2048);
    CHECK(o.motion->animated());
  }
  CHECK(s.frame_count == 60);
  CHECK(s.width == 256);
  CHECK(s.height == 256);
}

TEST_CASE("paper scenes: room is 35108 triangles in 32 very unequal objects - a few animated", "[generate][paper]") {
  const Scene s = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  CHECK(s.triangle_count() == 35108);
  REQUIRE(s.objects.size() == 32);
  std::size_t lo = s.objects[0].mesh.triangles.size(), hi = lo;
  int animated = 0;
  for (const Object& o : s.objects) {
    lo = std::min(lo, o.mesh.triangles.size());
    hi = std::max(hi, o.mesh.triangles.size());
    animated += o.motion->animated() ? 1 : 0;
  }
  CHECK(lo == 2);       // walls, floor, ceiling
  CHECK(hi >= 5000);    // the finely tessellated pieces
  CHECK(animated == 3);  // door, ceiling fan, ball
  CHECK(s.frame_count == 60);
  CHECK(s.width == 256);
  CHECK(s.height == 256);
}
