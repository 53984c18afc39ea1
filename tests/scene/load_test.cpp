#include "base/error.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace oprt;

namespace {
const std::string kData = std::string(OPRT_SOURCE_DIR) + "/tests/data/scenes/";

// Writes `text` to a scene file beside the test data (so relative OBJ paths resolve).
struct TempScene {
  std::string path;
  explicit TempScene(const std::string& text, const std::string& ext = ".json") {
    static int n = 0;  // unique per process and file: ctest runs cases in parallel
    path = (std::filesystem::temp_directory_path() / ("oprt_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ext)).string();
    std::ofstream(path) << text;
  }
  ~TempScene() { std::remove(path.c_str()); }
};

const char* kHead = R"("format": "oprt-scene/1", "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]})";
std::string with_objects(const std::string& objects, const std::string& extra = "") {
  return std::string("{") + kHead + extra + ", \"objects\": [" + objects + "]}";
}
const char* kTri = R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}})";

// Loading must fail with an InputError naming the place and the problem.
void expect_error(const std::string& text, const std::string& place, const std::string& problem) {
  TempScene s(text);
  try {
    load_scene(s.path);
    FAIL("no error for: " << text);
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == s.path);
    CHECK(e.place().find(place) != std::string::npos);
    CHECK(e.problem().find(problem) != std::string::npos);
  }
}
}  // namespace

TEST_CASE("scene: the DESIGN example loads with its contents", "[load]") {
  const Scene s = load_scene(kData + "small.json");
  CHECK(s.width == 64);
  CHECK(s.height == 48);
  CHECK(s.frame_count == 31);
  REQUIRE(s.objects.size() == 3);
  CHECK(s.objects[0].name == "cube");
  CHECK(s.objects[0].mesh.triangles.size() == 12);  // 6 quads
  CHECK(s.objects[1].mesh.triangles.size() == 1);
  CHECK(s.objects[2].mesh.triangles.size() == 100);
  CHECK(s.triangle_count() == 113);
  CHECK(s.materials[s.objects[0].material].name == "red");
  CHECK(s.materials[s.objects[1].material].name == "default");
  CHECK(s.lights.size() == 1);
  CHECK(s.background.z == 0.3);
  // The matrix transform places the triangle at x - 2.
  CHECK(s.objects[1].motion->at(0).point({1, 0, 0}).x == -1);
  // The cube moves: frame 30 is the last key.
  const Vec3d p30 = s.objects[0].motion->at(30).point({0, 0, 0});
  CHECK(p30.x == Approx(1));
  CHECK(s.objects[0].motion->animated());
  CHECK_FALSE(s.objects[1].motion->animated());
}

TEST_CASE("scene: malformed files fail with file - place and problem", "[load]") {
  expect_error("{\"format\": ", "line 1", "malformed JSON");
  expect_error("{\n\"format\": \"oprt-scene/1\",\n  \"camera\": [1,,2]}", "line 3", "malformed JSON");
  expect_error("[1, 2]", "/", "expected an object");
  expect_error(std::string("{") + kHead + ", \"objects\": [], \"colour\": 1}", "/colour", "unknown key");
  expect_error(R"({"format": "oprt-scene/2", "camera": {}, "objects": []})", "/format", "unsupported format");
  expect_error(std::string("{") + kHead + "}", "/", "missing required key \"objects\"");
  expect_error(with_objects(kTri, ", \"image\": {\"width\": \"wide\", \"height\": 4}"), "/image/width",
               "expected an integer");
  expect_error(with_objects(kTri, ", \"image\": {\"width\": 0, \"height\": 4}"), "/image/width", "out of range");
  expect_error(with_objects(R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,3]]}})"),
               "/objects/0/mesh/triangles/0/2", "out of range");
  expect_error(with_objects(R"({"mesh": {"vertices": [[0,0,1e999],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}})"),
               "line 1, column 123", "number overflow parsing '1e999' (numbers must be finite)");
  expect_error(with_objects(R"({"mesh": {"vertices": [[0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}})"),
               "/objects/0/mesh/vertices/0", "array of 3 numbers");
  expect_error(with_objects(R"({"material": "gold", "mesh": {"generate": {"kind": "box"}}})"),
               "/objects/0/material", "unknown material");
  expect_error(with_objects(R"({"mesh": {"generate": {"kind": "teapot"}}})"), "/objects/0/mesh/generate/kind",
               "unknown generator");
  expect_error(with_objects(R"({"mesh": {"obj": "no_such.obj"}})"), "", "cannot open");
  expect_error(with_objects(R"({"mesh": {"generate": {"kind": "box"}}, "transform": {"matrix": [1,0,0,0, 0,0,0,0, 0,0,1,0]}})"),
               "/objects/0/transform/matrix", "singular");
  expect_error(with_objects(R"({"mesh": {"generate": {"kind": "box"}}, "transform": {"scale": 0}})"),
               "/objects/0/transform/scale", "out of range");
  expect_error(with_objects(R"({"mesh": {"generate": {"kind": "box"}}, "animation": {"keyframes": [{"frame": 5}, {"frame": 2}]}})"),
               "/objects/0/animation/keyframes/1/frame", "increasing");
  expect_error(with_objects(R"({"mesh": {"vertices": [], "triangles": []}})"), "/objects/0/mesh", "no triangles");
  expect_error(R"({"format": "oprt-scene/1", "camera": {"eye": [0,0,0], "target": [0,0,0]}, "objects": []})",
               "/camera", "coincide");
}

TEST_CASE("scene: missing files and unknown extensions", "[load]") {
  CHECK_THROWS_AS(load_scene("/nonexistent/scene.json"), InputError);
  TempScene s("hello", ".txt");
  try {
    load_scene(s.path);
    FAIL("loaded a .txt");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("unknown scene format") != std::string::npos);
  }
}

TEST_CASE("scene: OBJ errors name the file and the face", "[load][obj]") {
  TempScene bad("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", ".obj");
  try {
    load_obj(bad.path);
    FAIL("loaded an out-of-range index");
  } catch (const InputError& e) {
    CHECK(e.file() == bad.path);
    CHECK(e.problem().find("out of range") != std::string::npos);
  }
  TempScene nan("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", ".obj");
  CHECK_THROWS_AS(load_obj(nan.path), InputError);
  TempScene empty("# nothing\n", ".obj");
  CHECK_THROWS_AS(load_obj(empty.path), InputError);
}

TEST_CASE("scene: materials read reflect, transmit and ior", "[load][materials]") {
  const std::string text = std::string("{") + kHead +
                           R"(, "materials": {
      "mirror": {"diffuse": [0.1, 0.1, 0.1], "reflect": 0.8},
      "glass": {"reflect": [0.1, 0.2, 0.3], "transmit": 0.9, "ior": 1.5},
      "tinted": {"transmit": [1, 0.5, 0], "ior": 10},
      "plain": {"specular": [0.5, 0.5, 0.5]}},
    "objects": [{"material": "mirror", "mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}}]})";
  TempScene f(text);
  const Scene s = load_scene(f.path);
  REQUIRE(s.materials.size() == 4);
  auto named = [&](const std::string& n) -> const Material& {
    for (const Material& m : s.materials)
      if (m.name == n) return m;
    FAIL("no material " << n);
    throw;
  };
  const Material &mirror = named("mirror"), &glass = named("glass"), &tinted = named("tinted"), &plain = named("plain");
  CHECK(mirror.reflect == Vec3d(0.8));
  CHECK(mirror.transmit == Vec3d(0));
  CHECK(mirror.ior == 1);
  CHECK(mirror.diffuse == Vec3d(0.1));  // the Phong terms as before
  CHECK(glass.reflect == Vec3d(0.1, 0.2, 0.3));
  CHECK(glass.transmit == Vec3d(0.9));
  CHECK(glass.ior == 1.5);
  CHECK(tinted.transmit == Vec3d(1, 0.5, 0));
  CHECK(tinted.ior == 10);
  CHECK_FALSE(tinted.reflects());
  CHECK(tinted.transmits());
  // A specular highlight is not a mirror: reflect stays 0 unless given.
  CHECK_FALSE(plain.reflects());
  CHECK_FALSE(plain.transmits());
  CHECK(plain.ior == 1);
}

TEST_CASE("scene: bad reflect, transmit and ior name their JSON pointer", "[load][materials][errors]") {
  auto with_material = [](const std::string& m) {
    return std::string("{") + kHead + R"(, "materials": {"m": )" + m + R"(}, "objects": [)" + kTri + "]}";
  };
  expect_error(with_material(R"({"reflect": 1.5})"), "/materials/m/reflect", "out of range [0, 1]");
  expect_error(with_material(R"({"reflect": -0.1})"), "/materials/m/reflect", "out of range [0, 1]");
  expect_error(with_material(R"({"reflect": [0.1, 0.2]})"), "/materials/m/reflect", "expected a number or 3 numbers");
  expect_error(with_material(R"({"transmit": [0.1, 2, 0.3]})"), "/materials/m/transmit/1", "out of range [0, 1]");
  expect_error(with_material(R"({"transmit": "clear"})"), "/materials/m/transmit", "expected a number or 3 numbers");
  expect_error(with_material(R"({"ior": 0.5})"), "/materials/m/ior", "out of range [1, 10]");
  expect_error(with_material(R"({"ior": 11})"), "/materials/m/ior", "out of range [1, 10]");
  expect_error(with_material(R"({"mirror": 1})"), "/materials/m/mirror", "unknown key");
}

TEST_CASE("scene: an OBJ face one past the last vertex is refused, also where the line check skips it", "[load][obj]") {
  // Three vertices, a face naming vertex 4. The line check reads lines that start with "f ";
  // an indented face line is parsed by the OBJ reader all the same, and the index check after
  // it must still refuse vertex 4 of 3 (0-based 3: one past the last).
  for (const char* face : {"f 1 2 4\n", "  f 1 2 4\n"}) {
    INFO(face);
    TempScene bad(std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\n") + face, ".obj");
    try {
      load_obj(bad.path);
      FAIL("loaded vertex 4 of 3");
    } catch (const InputError& e) {
      CHECK(e.file() == bad.path);
      CHECK(e.problem().find("vertex index 4 out of range") != std::string::npos);
    }
  }
}

TEST_CASE("scene: keyframes at the same frame are refused and a key without a translation keeps the last", "[load]") {
  expect_error(with_objects(R"({"mesh": {"generate": {"kind": "box"}}, "animation": {"keyframes": [{"frame": 5}, {"frame": 5}]}})"),
               "/objects/0/animation/keyframes/1/frame", "increasing");
  // Keys at 0 (+(1, 2, 3)) and 10 (a turn about z, no translation given): the object stays at
  // +(1, 2, 3) while it turns. Frame 10: (1,0,0) -> 90 degrees -> (0,1,0) -> (1, 3, 3).
  TempScene s(with_objects(R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]},
      "animation": {"keyframes": [{"frame": 0, "translate": [1, 2, 3]},
                                  {"frame": 10, "rotate": {"axis": [0, 0, 1], "deg": 90}}]}})",
                           R"(, "frames": 11)"));
  const Scene scene = load_scene(s.path);
  REQUIRE(scene.objects.size() == 1);
  const Vec3d p = scene.objects[0].motion->at(10).point({1, 0, 0});
  CHECK(p.x == Approx(1));
  CHECK(p.y == Approx(3));
  CHECK(p.z == Approx(3));
  CHECK(scene.objects[0].motion->at(5).point({0, 0, 0}).x == Approx(1));
}

TEST_CASE("scene: an animated object's keyframes move the object placed by its transform", "[load]") {
  // Placed +(1, 0, 0) by "transform", then turned 90 degrees about z by its only keyframe:
  // world = animation(f) x placement, so the origin goes to (1,0,0) and then to (0,1,0).
  // (Placement after animation would leave it at (1,0,0).)
  TempScene s(with_objects(R"({"mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]},
      "transform": {"translate": [1, 0, 0]},
      "animation": {"keyframes": [{"frame": 0, "rotate": {"axis": [0, 0, 1], "deg": 90}}]}})"));
  const Scene scene = load_scene(s.path);
  REQUIRE(scene.objects.size() == 1);
  const Vec3d p = scene.objects[0].motion->at(0).point({0, 0, 0});
  CHECK(p.x == Approx(0).margin(1e-12));
  CHECK(p.y == Approx(1));
  CHECK(p.z == Approx(0).margin(1e-12));
}
