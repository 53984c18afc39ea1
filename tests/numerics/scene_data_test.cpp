// NaN and infinity in scene data are refused with an InputError naming the place, by every
// loader, before any kernel sees them. Already covered elsewhere: JSON can spell neither
// (the parser refuses NaN, Infinity and 1e999: tests/scene/load_test.cpp), BART .aff 'nan',
// 'inf', 1e999 (aff_test.cpp), glTF NaN and infinite accessor elements and 1e999 in the JSON
// (gltf_test.cpp), NaN and infinite matrices (geom/affine_test.cpp). The gaps closed here:
// OBJ infinities, matrices whose determinant overflows, and data that is finite in double
// but not in the precision the engine runs (float).
#include "balance/spheres.h"
#include "ref/frame_setup.h"
#include "base/error.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace oprt;

namespace {
struct TempFile {
  std::string path;
  TempFile(const std::string& text, const std::string& ext) {
    static int n = 0;  // unique per process and file: ctest runs cases in parallel
    path = (std::filesystem::temp_directory_path() / ("oprt_numerics_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ext)).string();
    std::ofstream(path) << text;
  }
  ~TempFile() { std::remove(path.c_str()); }
};

template <typename F>
void expect_input_error(F&& f, const std::string& place, const std::string& problem) {
  try {
    f();
    FAIL("no error");
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.place().find(place) != std::string::npos);
    CHECK(e.problem().find(problem) != std::string::npos);
  }
}

std::string scene_json(const std::string& vertex, const std::string& matrix_diagonal) {
  return R"({"format": "oprt-scene/1", "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},
    "objects": [{"name": "tri", "mesh": {"vertices": [[0, 0, 0], [)" + vertex + R"(, 0, 0], [0, 1, 0]],
    "triangles": [[0, 1, 2]]}, "transform": {"matrix": [)" + matrix_diagonal + ", 0, 0, 0,  0, " + matrix_diagonal +
         ", 0, 0,  0, 0, " + matrix_diagonal + ", 0]}}]}";
}
}  // namespace

TEST_CASE("scene data: OBJ coordinates nan, inf and 1e999 are refused with their line", "[numerics][load]") {
  for (const char* bad : {"nan", "inf", "-inf", "1e999", "-1e999", "NaN", "infinity"}) {
    INFO(bad);
    TempFile obj(std::string("v 0 0 0\nv 1 0 0\nv 0 1 ") + bad + "\nf 1 2 3\n", ".obj");
    expect_input_error([&] { load_obj(obj.path); }, "line 3", "not");
  }
}

TEST_CASE("scene data: a matrix whose determinant overflows is refused at load", "[numerics][load]") {
  TempFile s(scene_json("1", "1e300"), ".json");
  expect_input_error([&] { load_scene(s.path); }, "/objects/0/transform/matrix", "overflows");
}

TEST_CASE("scene data: finite in double but not in float - refused when the engine runs in float",
          "[numerics][load]") {
  // The loaders refuse coordinates beyond +-1e18 (a float kernel would square them to
  // infinity); build_geometry<float> still guards against what a program can put into a
  // Scene directly, past the loaders.
  {
    TempFile s(scene_json("1e39", "1"), ".json");
    expect_input_error([&] { load_scene(s.path); }, "object 0 (\"tri\") vertex 1", "beyond +-1e18");
  }
  {  // A vertex beyond float's range (3.4e38).
    TempFile s(scene_json("1", "1"), ".json");
    Scene scene = load_scene(s.path);
    scene.objects[0].mesh.vertices[1] = {1e39, 0, 0};
    expect_input_error([&] { build_geometry<float>(scene, make_spheres(scene, 1)); }, "object 0 (\"tri\") triangle 0",
                       "beyond the range of float precision");
    for (Kernel k : {Kernel::moller, Kernel::watertight})
      expect_input_error([&] { build_geometry<float>(scene, make_spheres(scene, 1), k); }, "triangle 0", "float");
    CHECK_NOTHROW(build_geometry<double>(scene, make_spheres(scene, 1)));
  }
  {  // Vertices in float's range whose Moller normal (edge x edge, 1e40) is not; watertight
     // stores only the vertices.
    TempFile s(scene_json("1", "1"), ".json");
    Scene scene = load_scene(s.path);
    scene.objects[0].mesh.vertices = {{0, 0, 0}, {1e20, 0, 0}, {0, 1e20, 0}};
    expect_input_error([&] { build_geometry<float>(scene, make_spheres(scene, 1), Kernel::moller); }, "triangle 0",
                       "normal");
    CHECK_NOTHROW(build_geometry<float>(scene, make_spheres(scene, 1), Kernel::watertight));
  }
  {  // A scale of 1e-40: valid (well shaped), but its inverse, 1e40, is not a float.
    TempFile s(scene_json("1", "1e-40"), ".json");
    const Scene scene = load_scene(s.path);
    const SceneGeometry<float> g = build_geometry<float>(scene, make_spheres(scene, 1));
    expect_input_error([&] { setup_frame(scene, g, 0); }, "object 0 (\"tri\") at frame 0",
                       "inverse of the matrix is beyond the range of float precision");
    const SceneGeometry<double> gd = build_geometry<double>(scene, make_spheres(scene, 1));
    CHECK_NOTHROW(setup_frame(scene, gd, 0));
  }
}
