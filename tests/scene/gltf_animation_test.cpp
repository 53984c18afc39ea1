// glTF animation framed whole (issue 15), against tests/data/gltf/animated.gltf and
// camera_rig.gltf (made by make_gltf.py, whose build_animated docstring gives the scene): the
// default camera keeps every frame in view, lights and cameras ride their animated nodes, every
// animation plays; and a buffer uri that is no usable file name ends in the loader's own error.
#include "balance/spheres.h"
#include "ref/reference.h"
#include "base/error.h"
#include "scene/load.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <unistd.h>

using namespace oprt;
using nlohmann::json;

namespace {
const std::string kDir = std::string(OPRT_SOURCE_DIR) + "/tests/data/gltf/";

void check_point(const Vec3d& got, const Vec3d& want) {
  INFO("got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x << ", " << want.y << ", " << want.z
               << ")");
  CHECK(got.x == Approx(want.x).margin(1e-6));
  CHECK(got.y == Approx(want.y).margin(1e-6));
  CHECK(got.z == Approx(want.z).margin(1e-6));
}

const Object& object(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return o;
  FAIL("no object " << name);
  throw;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct TempFile {
  std::string path;
  explicit TempFile(const std::string& text) {
    static int n = 0;
    path = (std::filesystem::temp_directory_path() /
            ("oprt_gltf_anim_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ".gltf"))
               .string();
    std::ofstream(path, std::ios::binary) << text;
  }
  ~TempFile() { std::remove(path.c_str()); }
};
}  // namespace

TEST_CASE("gltf: the default camera frames every frame of the animation", "[gltf][animation]") {
  const Scene s = load_scene(kDir + "animated.gltf");
  CHECK(s.frame_count == 61);  // the last key at 2 s, 30 frames a second
  // Bounds over the animation (hand-computed in make_gltf.py): the floor, +-0.5; the cube from
  // y = 0.5 (frame 0) up to 8 (frame 60, scale 2), x and z within +-1. Centre (0, 3.75, 0),
  // radius half the diagonal of (2, 8.5, 2); the eye as far along +Z as a 45 degree view needs.
  const Camera c = s.camera->at(0);
  const double radius = 0.5 * std::sqrt(2 * 2 + 8.5 * 8.5 + 2 * 2);
  check_point(c.target, {0, 3.75, 0});
  check_point(c.eye, {0, 3.75, radius / std::sin(22.5 * M_PI / 180)});
  CHECK(c.fov_y_deg == 45);
  // Every vertex of every object at every frame is in the view cone; the frame-0 bounds
  // (y up to 1.5) would leave the risen cube (y = 8 at frame 60) above the picture.
  const double half = 22.5 * M_PI / 180;
  for (int f = 0; f < s.frame_count; ++f)
    for (const Object& o : s.objects)
      for (const Vec3d& v : o.mesh.vertices) {
        const Vec3d w = o.motion->at(f).point(v) - c.eye;
        CHECK(std::atan2(std::fabs(w.y), -w.z) < half);
        CHECK(std::atan2(std::fabs(w.x), -w.z) < half);
      }
  // So the rising cube changes the picture: frames 0, 30 and 60 differ, and the cube is in
  // each of them (object ids of the primary hits, 24 x 24 pixels).
  const auto g = build_geometry<double>(s, make_spheres(s, 1));
  std::vector<std::vector<std::uint32_t>> ids;
  for (int f : {0, 30, 60}) {
    INFO("frame " << f);
    const FrameResult r = render_reference(s, g, f, 24, 24);
    ids.push_back(r.image.object);
    const std::set<std::uint32_t> seen(r.image.object.begin(), r.image.object.end());
    CHECK(seen.size() == 3);  // floor, cube and the background
  }
  CHECK(ids[0] != ids[1]);
  CHECK(ids[1] != ids[2]);
}

TEST_CASE("gltf: BoxAnimated's rising inner box stays in the default view", "[gltf][animation]") {
  // box_animated.gltf has BoxAnimated's nodes and animations: the inner box (inside the outer
  // one at frame 0) rises 2.52 by 1.25 s (frame 37.5) and is back at 3.708 s (frame 111.25).
  // Framed on frame 0 only, frames 30 and 60 showed the outer box alone, as frame 0 does.
  const Scene s = load_scene(kDir + "box_animated.gltf");
  CHECK(s.frame_count == 113);
  REQUIRE(s.objects.size() == 2);
  const auto g = build_geometry<double>(s, make_spheres(s, 1));
  std::vector<std::vector<std::uint32_t>> ids;
  for (int f : {0, 30, 60}) {
    INFO("frame " << f);
    const FrameResult r = render_reference(s, g, f, 24, 24);
    ids.push_back(r.image.object);
    const std::size_t inner = std::count(r.image.object.begin(), r.image.object.end(), 1u);
    const std::size_t outer = std::count(r.image.object.begin(), r.image.object.end(), 0u);
    CHECK(outer > 0);
    CHECK((inner > 0) == (f > 0));  // risen out of the outer box, and in view
  }
  CHECK(ids[0] != ids[1]);
  CHECK(ids[0] != ids[2]);
}

TEST_CASE("gltf: every animation plays, a light follows its node", "[gltf][animation]") {
  const Scene s = load_scene(kDir + "animated.gltf");
  // LINEAR lift (y = 3 t) and STEP scale (2 from 1 s) together carry the cube's corner
  // (0.5, 0.5, 0.5): lift(t) * T(0,1,0) * S(scale).
  const Object& cube = object(s, "cube");
  check_point(cube.motion->at(0).point({0.5, 0.5, 0.5}), {0.5, 1.5, 0.5});
  check_point(cube.motion->at(15).point({0.5, 0.5, 0.5}), {0.5, 3, 0.5});  // t = 0.5: scale still 1
  check_point(cube.motion->at(30).point({0.5, 0.5, 0.5}), {1, 5, 1});
  check_point(cube.motion->at(60).point({0.5, 0.5, 0.5}), {1, 8, 1});
  CHECK_FALSE(object(s, "floor").motion->animated());
  // The lamp, a child of the lift at T(0,2,0): at (0, 2 + 3 t, 0).
  REQUIRE(s.lights.size() == 1);
  const PointLight& lamp = s.lights[0];
  check_point(lamp.position, {0, 2, 0});  // frame 0
  for (int f : {0, 15, 30, 45, 60}) {
    INFO("frame " << f);
    check_point(lamp.at(f), {0, 2 + 3 * (f / 30.0), 0});
  }
  check_point(lamp.at(90), {0, 8, 0});  // after the last key: held
}

TEST_CASE("gltf: a camera on an animated node moves with it", "[gltf][animation]") {
  const Scene s = load_scene(kDir + "camera_rig.gltf");
  // CUBICSPLINE with zero tangents: x = 10 (3 s^2 - 2 s^3), s = t / 2; the eye 2 above the rig.
  for (const auto& [f, x] : std::vector<std::pair<int, double>>{{0, 0}, {15, 1.5625}, {30, 5}, {60, 10}}) {
    INFO("frame " << f);
    const Camera c = s.camera->at(f);
    check_point(c.eye, {x, 2, 20});
    check_point(glm::normalize(c.target - c.eye), {0, 0, -1});
    check_point(glm::normalize(c.up), {0, 1, 0});
  }
  CHECK(s.camera->at(0).fov_y_deg == Approx(0.7 * 180 / M_PI));
  // The other two animations play alongside.
  check_point(object(s, "cube").motion->at(30).point({0.5, 0.5, 0.5}), {1, 5, 1});
}

TEST_CASE("gltf: an animated directional light turns with its node", "[gltf][animation]") {
  // The lamp turns about Y from 0 to 90 degrees over 2 s: its -Z goes to -X, so its far
  // stand-in, against -Z, goes from +Z (frame 0) to +X (frame 60), 45 degrees halfway, 1000
  // scene radii from the centre of the animation's bounds (0, 3.75, 0).
  json d = json::parse(slurp(kDir + "animated.gltf"));
  d["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "directional";
  TempFile f(d.dump());
  const Scene s = load_scene(f.path);
  REQUIRE(s.lights.size() == 1);
  const Vec3d centre(0, 3.75, 0);
  const Vec3d a = s.lights[0].at(0) - centre, m = s.lights[0].at(30) - centre, b = s.lights[0].at(60) - centre;
  const double far = 1000 * 0.5 * std::sqrt(2 * 2 + 8.5 * 8.5 + 2 * 2);
  check_point(a, {0, 0, far});
  check_point(m, {far * std::sqrt(0.5), 0, far * std::sqrt(0.5)});
  check_point(b, {far, 0, 0});
  check_point(s.lights[0].position, centre + Vec3d(0, 0, far));  // frame 0
}

TEST_CASE("gltf: a buffer uri that is neither a data URI nor a file name ends in the loader's error",
          "[gltf][errors]") {
  const json base = json::parse(slurp(kDir + "animated.gltf"));
  const std::string data = base["buffers"][0]["uri"];
  struct Case {
    std::string uri, problem;
  };
  const std::vector<Case> cases = {
      {std::string(5000, 'a'), "neither a data URI nor a usable file name: \"aaaa"},
      {std::string(600, 'a') + "/" + std::string(600, 'b'), "has a part of 600 bytes"},
      {"data:application/octet-stream;base64" + data.substr(data.find(',') + 1), "only base64 data URIs"},
      {"dat" + data.substr(4), "cannot open buffer file"},
      {"x%00y.bin", "contains a NUL byte"},
      {"", "the uri is empty"},
      {".", "not a regular file"},
  };
  for (const Case& c : cases) {
    INFO(c.uri.substr(0, 80));
    json d = base;
    d["buffers"][0]["uri"] = c.uri;
    TempFile f(d.dump());
    try {
      load_scene(f.path);
      FAIL("loaded");
    } catch (const InputError& e) {
      INFO(e.what());
      CHECK(e.file() == f.path);
      CHECK(e.place() == "/buffers/0/uri");
      CHECK(e.problem().find(c.problem) != std::string::npos);
      CHECK(std::string(e.what()).size() < 400);  // the uri is never echoed whole
    }
  }
  // Images are never opened (textures are ignored): a wild image uri does not matter.
  json d = base;
  d["images"] = {{{"uri", std::string(5000, 'a')}}};
  TempFile f(d.dump());
  CHECK(load_scene(f.path).objects.size() == 2);
}
