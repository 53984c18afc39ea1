#include "ref/camera.h"
#include "ref/reference.h"
#include "scene/aff.h"
#include "base/error.h"
#include "scene/kb_spline.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include <unistd.h>

using namespace oprt;

namespace {
namespace fs = std::filesystem;

const std::string kData = std::string(OPRT_SOURCE_DIR) + "/tests/data/aff/";
const std::string kBart = std::string(OPRT_SHARED_DIR) + "/bart/";
constexpr double kPi = 3.14159265358979323846;

// A scratch directory for generated AFF files, removed afterwards.
struct TempDir {
  fs::path dir;
  TempDir() {
    // Unique per process and per directory: ctest runs test cases in parallel processes,
    // and ::rand() would give every process the same name.
    static int n = 0;
    dir = fs::temp_directory_path() / ("oprt_aff_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
    fs::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p.lexically_normal().string();
  }
};

const char* kView = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 0.1 resolution 8 8\n";
const char* kTri = "p 3\n0 0 0\n1 0 0\n0 1 0\n";

const Object& named(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return o;
  FAIL("no object named " << name);
  throw std::logic_error("unreachable");
}

bool has_note(const Scene& s, const std::string& part) {
  return std::any_of(s.notes.begin(), s.notes.end(), [&](const std::string& n) { return n.find(part) != std::string::npos; });
}

// Loading `text` (as bad.aff, beside `extra` files) must fail naming the file, the line and
// the problem.
void expect_error(const std::string& text, int line, const std::string& problem,
                  const std::vector<std::pair<std::string, std::string>>& extra = {}, std::string file = "") {
  TempDir d;
  const std::string path = d.write("bad.aff", text);
  for (const auto& [name, body] : extra) d.write(name, body);
  const std::string expected_file = file.empty() ? path : (d.dir / file).lexically_normal().string();
  try {
    load_scene(path);
    FAIL("no error for:\n" << text);
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == expected_file);
    CHECK(e.place() == "line " + std::to_string(line));
    CHECK(e.problem().find(problem) != std::string::npos);
  }
}

Vec3d rot_z(const Vec3d& v, double deg) {
  const double a = deg * kPi / 180;
  return {v.x * std::cos(a) - v.y * std::sin(a), v.x * std::sin(a) + v.y * std::cos(a), v.z};
}
}  // namespace

// ----------------------------------------------------------------------------------------
// Kochanek-Bartels splines against values worked out by hand

TEST_CASE("kb: zero tension continuity and bias with even keys is Catmull-Rom", "[aff][kb]") {
  // P = 0 1 2 4 at t = 0 1 2 3. Catmull-Rom on the middle segment:
  // P(u) = ((2 P1) + (P2 - P0) u + (2 P0 - 5 P1 + 4 P2 - P3) u^2 + (-P0 + 3 P1 - 3 P2 + P3) u^3) / 2
  //      = (2 + 2u - u^2 + u^3) / 2.
  const KbVecSpline s({{0, {0, 0, 0}, {}}, {1, {1, 10, 0}, {}}, {2, {2, 20, 0}, {}}, {3, {4, 40, 0}, {}}});
  CHECK(s.start() == 1);
  CHECK(s.end() == 2);
  CHECK(s.at(1).x == Approx(1));
  CHECK(s.at(2).x == Approx(2));
  CHECK(s.at(1.5).x == Approx(1.4375));     // (-P0 + 9 P1 + 9 P2 - P3) / 16 = 23 / 16
  CHECK(s.at(1.25).x == Approx(1.2265625));  // (2 + 0.5 - 0.0625 + 0.015625) / 2
  CHECK(s.at(1.75).x == Approx(1.6796875));  // (2 + 1.5 - 0.5625 + 0.421875) / 2
  CHECK(s.at(1.5).y == Approx(14.375));      // each coordinate on its own
  // Outside the middle segment the curve holds its end keys (the outer keys only shape it).
  CHECK(s.at(0).x == Approx(1));
  CHECK(s.at(-100).x == Approx(1));
  CHECK(s.at(3).x == Approx(2));
  CHECK(s.at(1e9).x == Approx(2));
}

TEST_CASE("kb: uneven key spacing rescales the tangents", "[aff][kb]") {
  // P = t at t = -1 0 4 5: with tangents rescaled by 2 (t2 - t1) / (t2 - t0) = 1.6 and
  // 2 (t2 - t1) / (t3 - t1) = 1.6, Tout = 0.8 (1 + 4) = 4 = Tin = D: exactly linear.
  const KbVecSpline s({{-1, {-1, 0, 0}, {}}, {0, {0, 0, 0}, {}}, {4, {4, 0, 0}, {}}, {5, {5, 0, 0}, {}}});
  for (double t : {0.0, 0.5, 1.0, 2.0, 3.3, 4.0}) CHECK(s.at(t).x == Approx(t).margin(1e-12));
}

TEST_CASE("kb: tension continuity and bias", "[aff][kb]") {
  const std::vector<double> p = {0, 1, 2, 4};
  auto spline = [&](KbParams k1, KbParams k2) {
    return KbVecSpline({{0, {p[0], 0, 0}, {}}, {1, {p[1], 0, 0}, k1}, {2, {p[2], 0, 0}, k2}, {3, {p[3], 0, 0}, {}}});
  };
  // Tension 1: zero tangents, P(u) = P1 + (3u^2 - 2u^3) D; at u = 0.25: 1 + 0.15625.
  CHECK(spline({1, 0, 0}, {1, 0, 0}).at(1.25).x == Approx(1.15625));
  // Bias 1 at both keys: Tout = (P1 - P0) = 1, Tin = (P2 - P1) = 1: P(u) = 1 + u.
  CHECK(spline({0, 0, 1}, {0, 0, 1}).at(1.5).x == Approx(1.5));
  // Bias -1: Tout = P2 - P1 = 1, Tin = P3 - P2 = 2: c2 = 3 - 2 - 2 = -1, c3 = -2 + 1 + 2 = 1;
  // at u = 0.5: 1 + 0.5 - 0.25 + 0.125.
  CHECK(spline({0, 0, -1}, {0, 0, -1}).at(1.5).x == Approx(1.375));
  // Continuity -1: Tout = P2 - P1 = 1 (out1 = 1), Tin = P2 - P1 = 1 (in0 = 1): linear.
  CHECK(spline({0, -1, 0}, {0, -1, 0}).at(1.5).x == Approx(1.5));
}

TEST_CASE("kb: keys at the same time make a jump and never a NaN", "[aff][kb]") {
  // Keys 2 and 3 share t = 2 (the kitchen's wheels have such pairs): the segment between
  // them is never entered, the curve reaches 2 at t -> 2 and continues from 5.
  const KbVecSpline s({{0, {0, 0, 0}, {}},
                       {1, {1, 0, 0}, {}},
                       {2, {2, 0, 0}, {}},
                       {2, {5, 0, 0}, {}},
                       {3, {6, 0, 0}, {}},
                       {4, {7, 0, 0}, {}}});
  CHECK(s.at(1).x == Approx(1));
  CHECK(s.at(2 - 1e-9).x == Approx(2));
  CHECK(s.at(2).x == Approx(5));  // at the shared time the later key holds, as in BART
  CHECK(s.at(3).x == Approx(6));
  for (double t = 0; t <= 4; t += 0.125) CHECK(std::isfinite(s.at(t).x));
  CHECK_THROWS_AS(KbVecSpline({{0, {}, {}}, {1, {}, {}}, {2, {}, {}}}), std::invalid_argument);
}

TEST_CASE("kb: rotation at a constant rate about one axis interpolates the angle", "[aff][kb]") {
  // Equal steps about one axis: the tangents equal the step, so a = q1 and b = q2 and squad
  // is the slerp: 90 + 90 u degrees. The angles go past 360 (the kitchen's wheels do).
  const KbRotSpline s({{0, {0, 0, 2}, 180, {}}, {1, {0, 0, 2}, 270, {}}, {2, {0, 0, 2}, 360, {}},
                       {3, {0, 0, 2}, 450, {}}});
  const Vec3d x(1, 0, 0);
  for (double u : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    const Vec3d r = rotation_matrix(s.at(1 + u)).vector(x);
    const Vec3d e = rot_z(x, 270 + 90 * u);
    CHECK(r.x == Approx(e.x).margin(1e-12));
    CHECK(r.y == Approx(e.y).margin(1e-12));
    CHECK(r.z == Approx(0).margin(1e-12));
  }
  CHECK(rotation_matrix(s.at(-5)).vector(x).y == Approx(-1));  // held at 270 degrees
}

TEST_CASE("kb: quaternion log and exp invert each other", "[aff][kb]") {
  const Quatd q = glm::normalize(Quatd(0.3, -0.5, 0.7, 0.2));
  const Quatd r = quat_exp(quat_log(q));
  CHECK(r.w == Approx(q.w));
  CHECK(r.x == Approx(q.x));
  CHECK(r.y == Approx(q.y));
  CHECK(r.z == Approx(q.z));
  const Quatd id = quat_exp(quat_log(Quatd(1, 0, 0, 0)));
  CHECK(id.w == 1);
}

// ----------------------------------------------------------------------------------------
// Small handwritten scenes

TEST_CASE("aff: a keyframe track moves its object by the hand-computed values", "[aff]") {
  const Scene s = load_scene(kData + "spline.aff");
  CHECK(s.width == 32);
  CHECK(s.height == 24);
  CHECK(s.frame_count == 3);
  CHECK(s.background.z == 0.3);
  REQUIRE(s.lights.size() == 2);
  CHECK(s.lights[0].color == Vec3d(1));
  CHECK(s.lights[1].color == Vec3d(0.5, 0.25, 1));
  REQUIRE(s.objects.size() == 1);
  const Object& o = s.objects[0];
  CHECK(o.name == "mover/m0");
  REQUIRE(s.materials.size() == 1);
  CHECK(s.materials[0].diffuse == Vec3d(0.5));
  CHECK(s.materials[0].specular == Vec3d(0.2));
  CHECK(s.materials[0].shininess == 16);
  CHECK(s.ambient.x == Approx(0.1));  // am 0.5 x (ambient / diffuse = 0.2)
  CHECK(o.motion->animated());
  // `a 1 2 3`: frames 0 1 2 are times 1 1.5 2; frame 0.5 is time 1.25.
  struct Expect {
    double frame, x, deg;
  };
  for (const Expect& e : {Expect{0, 1, 90}, Expect{1, 1.4375, 135}, Expect{2, 2, 180}, Expect{0.5, 1.2265625, 112.5}}) {
    INFO("frame " << e.frame);
    const Affine<double> m = o.motion->at(e.frame);
    const Vec3d p = m.point({1, 0, 0});
    const Vec3d want = Vec3d(e.x, 0, 0) + rot_z({1, 0, 0}, e.deg);
    CHECK(p.x == Approx(want.x).margin(1e-12));
    CHECK(p.y == Approx(want.y).margin(1e-12));
    CHECK(p.z == Approx(0).margin(1e-12));
  }
}

TEST_CASE("aff: a non-uniform scale with a rotation scales first and then rotates (BART's T R S)", "[aff]") {
  // Scale (2, 1, 1), then 90 degrees about z, then +(10, 0, 0): (1,0,0) -> (2,0,0) -> (0,2,0)
  // -> (10,2,0); (0,1,0) -> (0,1,0) -> (-1,0,0) -> (9,0,0). Rotating first would put (1,0,0) at
  // (10,1,0) and (0,1,0) at (8,0,0).
  const auto world_points = [](const Scene& s, double frame) {
    REQUIRE(s.objects.size() == 1);
    const Object& o = s.objects[0];
    std::vector<Vec3d> p;
    for (const Vec3d& v : o.mesh.vertices) p.push_back(o.motion->at(frame).point(v));
    return p;
  };
  const auto holds = [](const std::vector<Vec3d>& points, const Vec3d& want) {
    for (const Vec3d& p : points)
      if (std::fabs(p.x - want.x) < 1e-9 && std::fabs(p.y - want.y) < 1e-9 && std::fabs(p.z - want.z) < 1e-9) return true;
    return false;
  };
  TempDir d;
  // A static transform (xs: scale, axis and angle, translation).
  const Scene still = load_scene(d.write("still.aff", std::string(kView) + "l 0 0 5\nf 1 1 1 1 0 1 0 1\n"
                                                                           "xs 2 1 1  0 0 1 90  10 0 0\n{\n" + kTri + "}\n"));
  auto p = world_points(still, 0);
  CHECK(holds(p, {10, 0, 0}));
  CHECK(holds(p, {10, 2, 0}));
  CHECK(holds(p, {9, 0, 0}));
  // Keyframes (k: scale and rot tracks of four keys, constant here; frames 0 and 1 are times 1
  // and 2, the curve's span): the same order, without the translation.
  const Scene moving = load_scene(d.write("moving.aff", std::string(kView) + "a 1 2 2\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n"
                                                                             "x mover\n{\n" + kTri + "}\n"
                                                                             "k mover\n{\nscale 4\n0 2 1 1 0 0 0\n1 2 1 1 0 0 0\n2 2 1 1 0 0 0\n3 2 1 1 0 0 0\n"
                                                                             "rot 4\n0 0 0 1 90 0 0 0\n1 0 0 1 90 0 0 0\n2 0 0 1 90 0 0 0\n3 0 0 1 90 0 0 0\n}\n"));
  for (double frame : {0.0, 0.5, 1.0}) {
    INFO("frame " << frame);
    p = world_points(moving, frame);
    CHECK(holds(p, {0, 0, 0}));
    CHECK(holds(p, {0, 2, 0}));   // (1,0,0); rotated first: (0,1,0)
    CHECK(holds(p, {-1, 0, 0}));  // (0,1,0); rotated first: (-2,0,0)
  }
}

TEST_CASE("aff: every construct loads with its known contents", "[aff]") {
  const Scene s = load_scene(kData + "features.aff");
  CHECK(s.frame_count == 5);
  CHECK(s.width == 64);
  REQUIRE(s.objects.size() == 5);
  CHECK(s.triangle_count() == 2 + 277 + 1 + 1 + 2);

  // Static geometry lands in world coordinates: (0,0,0) -> +(0,1,0) -> x2 -> 90 deg about z
  // -> +(10,0,0) = (8, 0, 0).
  const Object& red = named(s, "static/m0");
  CHECK_FALSE(red.motion->animated());
  CHECK(red.mesh.triangles.size() == 2);
  const Vec3d v0 = red.motion->at(0).point(red.mesh.vertices[red.mesh.triangles[0][0]]);
  CHECK(v0.x == Approx(8));
  CHECK(v0.y == Approx(0).margin(1e-12));
  CHECK(s.materials[red.material].diffuse == Vec3d(0.8, 0, 0));  // f: Kd x colour
  CHECK(s.materials[red.material].specular == Vec3d(0.2));       // f: Ks x white
  CHECK(s.materials[red.material].shininess == 10);

  CHECK(named(s, "static/m1").mesh.triangles.size() == 277);  // tt ttp pp m s c c
  CHECK(named(s, "static/m1").mesh.triangles_with_normals() == 4);  // ttp pp m (2)
  CHECK(s.materials[red.material].reflect == Vec3d(0.2));  // f: Ks, BART's reflection weight

  // outer: x = t. inner: 22.5 t degrees about y, after +5 along x, inside outer.
  const Object& outer = named(s, "outer/m2");
  const Object& inner = named(s, "outer/inner/m2");
  CHECK(outer.motion->at(1).point({0, 0, 0}).x == Approx(1));
  CHECK(outer.motion->at(2.5).point({0, 0, 0}).x == Approx(2.5));
  for (double f : {0.0, 1.0, 3.0}) {
    const double a = 22.5 * f * kPi / 180;
    const Vec3d p = inner.motion->at(f).point({1, 0, 0});
    CHECK(p.x == Approx(f + 5 + std::cos(a)));
    CHECK(p.y == Approx(0).margin(1e-12));
    CHECK(p.z == Approx(-std::sin(a)).margin(1e-12));
  }

  // tpa: linear between keys, held outside; the mesh is the frame-0 shape.
  const Object& tpa = named(s, "static/m3/tpa");
  REQUIRE(tpa.deform);
  REQUIRE(tpa.mesh.vertices.size() == 6);
  CHECK(tpa.mesh.triangles.size() == 2);
  std::vector<Vec3d> v;
  for (double f : {0.0, 1.0, 2.0, 2.5, 3.0, 4.0}) {
    tpa.deform->at(f, v);
    REQUIRE(v.size() == 6);
    const double z = std::clamp(2 * (f - 1), 0.0, 4.0);
    CHECK(v[0].z == Approx(z));
    CHECK(v[1] == Vec3d(1, 0, z));
    CHECK(v[3] == Vec3d(5, 5, 5));  // one key: never moves
  }
  tpa.deform->at(0, v);
  CHECK(v == tpa.mesh.vertices);

  // Camera: eye z = 10 + 3.2u + 1.6u^2 - 0.8u^3, u = t / 4; turned 90 degrees at t = 4.
  const Camera c0 = s.camera->at(0), c2 = s.camera->at(2), c4 = s.camera->at(4);
  CHECK(c0.eye.z == Approx(10));
  CHECK(c2.eye.z == Approx(11.9));
  CHECK(c4.eye.z == Approx(14));
  const Vec3d d0 = c0.target - c0.eye, d4 = c4.target - c4.eye;
  CHECK(d0.z == Approx(-1));
  CHECK(d4.x == Approx(-1));
  CHECK(d4.z == Approx(0).margin(1e-12));
  CHECK(c4.up.y == Approx(1));
  CHECK(c0.fov_y_deg == 40);

  // The animated light is at its translation keys' position: (3, 3, 3) at t = 0.
  REQUIRE(s.lights.size() == 1);
  CHECK(s.lights[0].at(0) == Vec3d(3, 3, 3));

  CHECK(has_note(s, "textures ignored"));
  CHECK(has_note(s, "vertex normals read"));
  CHECK(has_note(s, "interpolated for the lights' terms"));
  CHECK(has_note(s, "spheres tessellated: 224 triangles"));
  CHECK(has_note(s, "cones tessellated"));
  // inner's visibility keys: hidden from t = 1, shown again from t = 2 (frame f is t = f).
  const Object& hidden = named(s, "outer/inner/m2");
  CHECK(hidden.motion->visible(0));
  CHECK_FALSE(hidden.motion->visible(1));
  CHECK_FALSE(hidden.motion->visible(1.5));
  CHECK(hidden.motion->visible(2));
  CHECK(hidden.motion->visible(4));
  CHECK(outer.motion->visible(1));
  // The animated light `la lamp` follows its translation keys: (3, 3, 3) at t = 0, (7, 3, 3)
  // at t = 4, moving along x in between; frame f is t = f.
  REQUIRE(s.lights.size() == 1);
  CHECK(s.lights[0].at(0).x == Approx(3));
  CHECK(s.lights[0].at(0).y == Approx(3));
  CHECK(s.lights[0].at(4).x == Approx(7));
  CHECK(s.lights[0].at(4).z == Approx(3));
  for (int f = 0; f < 4; ++f) CHECK(s.lights[0].at(f + 1).x > s.lights[0].at(f).x);
  CHECK(std::count_if(s.notes.begin(), s.notes.end(),
                      [](const std::string& n) { return n.find("textures") != std::string::npos; }) == 1);
}

TEST_CASE("aff: a group hidden by visibility keys is absent from the frame and costs nothing", "[aff]") {
  TempDir d;
  const std::string path = d.write("blink.aff", std::string(kView) +
                                                    "a 0 4 5\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n"
                                                    "x blink\n{\np 4\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n}\n"
                                                    "k blink\n{\nvisibility 2\n1 0\n2 1\n}\n");
  const Scene s = load_scene(path);
  REQUIRE(s.objects.size() == 1);
  const auto g = build_geometry<float>(s, make_spheres(s, 1));
  const std::size_t centre = 4 * 8 + 4;
  for (int f = 0; f < 5; ++f) {
    INFO("frame " << f);
    const FrameResult r = render_reference(s, g, f, 8, 8);
    const bool shown = f != 1;  // hidden from t = 1 until t = 2
    CHECK((r.image.object[centre] == 0) == shown);
    // The sphere is not in the registers while hidden: no sphere test at all.
    CHECK((r.work.total().sphere_tests == 0) == !shown);
  }
}

TEST_CASE("aff: an animated light lights each frame from where its keys put it", "[aff]") {
  // A white plane z = 0 lit by one light, no ambient, no specular: a pixel's red is the
  // diffuse cosine, dot(n, normalize(light - p)) (model/ref/shading.cpp), with the light
  // moving from (0, 0, 1) at t = 0 to (8, 0, 1) at t = 4.
  TempDir d;
  const std::string path = d.write("lamp.aff", std::string(kView) +
                                                   "a 0 4 5\nam 0 0 0\nla lamp 0 0 0\nf 1 1 1 1 0 1 0 1\n"
                                                   "p 4\n-9 -9 0\n9 -9 0\n9 9 0\n-9 9 0\n"
                                                   "k lamp\n{\ntransl 4\n-1 0 0 1 0 0 0\n0 0 0 1 0 0 0\n"
                                                   "4 8 0 1 0 0 0\n5 8 0 1 0 0 0\n}\n");
  const Scene s = load_scene(path);
  const auto g = build_geometry<double>(s, make_spheres(s, 1));
  for (int f : {0, 2, 4}) {
    INFO("frame " << f);
    const FrameResult r = render_reference(s, g, f, 8, 8);
    const Vec3d light = s.lights.at(0).at(f);
    const CameraRays rays(s.camera->at(f), 8, 8);
    for (int px : {1, 4, 6}) {
      const std::size_t i = 4 * 8 + px;
      REQUIRE(r.image.object[i] == 0);
      const Ray<double> ray = rays.ray<double>(px, 4);
      const Vec3d p = ray.o + static_cast<double>(r.image.z[i]) * ray.d;
      const Vec3d l = glm::normalize(light - p);
      CHECK(r.image.r[i] == Approx(l.z).epsilon(1e-5));
    }
  }
  CHECK(s.lights[0].at(0).x == Approx(0));
  CHECK(s.lights[0].at(4).x == Approx(8));
}

TEST_CASE("aff: includes resolve relative to the including file", "[aff]") {
  const Scene s = load_scene(kData + "include/root.aff");
  REQUIRE(s.objects.size() == 1);
  const Mesh& m = s.objects[0].mesh;
  REQUIRE(m.triangles.size() == 4);  // root, a, b, c; the level-1 include is skipped
  std::vector<double> z;
  for (const Tri& t : m.triangles) z.push_back(m.vertices[t[0]].z);
  std::sort(z.begin(), z.end());
  CHECK(z == std::vector<double>{0, 1, 2, 3});
  CHECK(has_note(s, "detail level above 0 skipped"));
}

TEST_CASE("aff: large groups split into spatially separate parts", "[aff]") {
  // 100 triangles along x, at most 16 per object: median splits give 8 parts of 12 or 13
  // whose x ranges do not overlap.
  TempDir d;
  std::string text = std::string(kView) + "fm 0 0 0 1 1 1 0 0 0 0 0 0\n";
  for (int i = 0; i < 100; ++i) {
    const std::string x = std::to_string((i * 37) % 100);  // shuffled order in the file
    text += "p 3\n" + x + " 0 0\n" + x + ".5 0 0\n" + x + " 1 0\n";
  }
  AffOptions opt;
  opt.max_object_triangles = 16;
  const Scene s = load_aff(d.write("many.aff", text), opt);
  REQUIRE(s.objects.size() == 8);
  CHECK(s.triangle_count() == 100);
  std::vector<std::pair<double, double>> ranges;
  for (const Object& o : s.objects) {
    CHECK(o.mesh.triangles.size() <= 16);
    CHECK(o.mesh.vertices.size() == 3 * o.mesh.triangles.size());  // only the vertices it uses
    double lo = 1e9, hi = -1e9;
    for (const Vec3d& v : o.mesh.vertices) {
      lo = std::min(lo, v.x);
      hi = std::max(hi, v.x);
    }
    ranges.push_back({lo, hi});
  }
  std::sort(ranges.begin(), ranges.end());
  for (std::size_t i = 1; i < ranges.size(); ++i) CHECK(ranges[i - 1].second < ranges[i].first);
  opt.max_object_triangles = 0;  // never split
  CHECK(load_aff(d.write("many2.aff", text), opt).objects.size() == 1);
}

TEST_CASE("aff: malformed files name the file and the line and the problem", "[aff]") {
  const std::string v = kView;  // line 1
  expect_error(v + "zz 1 2\n", 2, "unknown keyword 'zz'");
  expect_error(v + "b 1 2\nl 0 0 0\n", 3, "wrong number of values for 'b' at line 2");
  expect_error(v + "b 1 2 3 4\n", 2, "wrong number of values: unexpected number '4' after 'b'");
  expect_error(v + "b 1 q 2\n", 2, "'q' is not a number");
  expect_error(v + "b 1 x 2\n", 2, "wrong number of values for 'b' at line 2");
  expect_error(v + "b 1 nan 2\n", 2, "'nan' is not a finite number");
  expect_error(v + "am inf 1 1\n", 2, "'inf' is not a finite number");
  expect_error(v + "b 1 1e999 1\n", 2, "not a finite number");
  expect_error(v + "l 0 0 0 1 1\n", 2, "a light's colour is 3 numbers");
  expect_error(v + "la\n", 2, "wrong number of values for 'la'");
  expect_error(v + "f 1 1 1 1 1\ns 0 0 0 1\n", 3, "wrong number of values for 'f'");
  expect_error(v + "fm 1 1 1 1 1 1 1 1 1 -5 0 0\n", 2, "Phong exponent");
  expect_error(v + "p 2\n0 0 0\n1 0 0\n", 2, "at least 3 vertices");
  expect_error(v + "p 3.5\n", 2, "'3.5' is not an integer");
  expect_error(v + "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0\n", 2, "vertex count 3 needs 18 values");
  expect_error(v + "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0\np 3\n0 0 0\n", 6, "wrong number of values for 'pp'");
  expect_error(v + "tt\n", 2, "expected a texture name");
  expect_error(v + "ttp tex\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 0\n", 4, "found the end of the file");
  expect_error(v + "m\nvertices 3\n0 0 0\n1 0 0\n0 1 0\ntriangles 1\n0 1 3\n", 8,
               "vertex index 3 of triangle 0 out of range: the mesh has 3 vertices");
  expect_error(v + "m\nvertices 3\n0 0 0\n1 0 0\n0 1 0\ntriangles 1\n0 1 -1\n", 8, "vertex index -1");
  expect_error(v + "m\nvertices 1\n0 0 0\nnormals 1\n0 0 1\ntriangles 1\n0 0 0  0 0 1\n", 8, "normal index 1");
  expect_error(v + "m\nvertices 3\n0 0 0\n1 0 0\n0 1 0\nfaces 1\n0 1 2\n", 7, "expected 'triangles', found 'faces'");
  expect_error(v + "m\nvertices 100000000\n0 0 0\n", 3, "needs 300000000 values");
  expect_error(v + "m\ntriangles 1\n", 3, "expected 'vertices', found 'triangles'");
  expect_error(v + "tpa 0\n", 2, "at least one key");
  expect_error(v + "s 0 0 0 0\n", 2, "sphere radius must not be zero");
  expect_error(v + "c 0 0 0 1 0 0 0 1\n", 2, "base and apex coincide");
  expect_error(v + "xs 0 1 1 0 1 0 0 0 0 0\n{\n}\n", 2, "static transform");
  expect_error(v + "xs 1 1 1 0 1 0 0 0 0 0\n{\n" + kTri, 3, "unterminated '{'");
  expect_error(v + "}\n", 2, "'}' without a matching '{'");
  expect_error(v + "{\n", 2, "unexpected '{'");
  expect_error(v + "x name\np 3\n", 3, "expected '{' after 'x' at line 2, found 'p'");
  expect_error(v + "a 0 1 0\n", 2, "number of frames 0 is out of range");
  expect_error(v + "d q\n", 2, "'q' is not a number");
  expect_error(v + "i 0 nothere.aff\n", 2, "cannot open included file 'nothere.aff'");
  expect_error(v + "k car\n{\ntransl 3\n0 0 0 0 0 0 0\n1 0 0 0 0 0 0\n2 0 0 0 0 0 0\n}\n", 4, "at least 4 keyframes");
  expect_error(v + "k car\n{\nspin 4\n}\n", 4, "unknown keyframe type 'spin'");
  expect_error(v + "k car\n{\nrot 4\n0 0 0 0 5 0 0 0\n1 0 1 0 0 0 0 0\n2 0 1 0 0 0 0 0\n3 0 1 0 0 0 0 0\n}\n", 5,
               "rotation axis is zero");
  expect_error(v + "k car\n{\nvisibility 1\n0 2\n}\n", 5, "visibility flag must be 0 or 1");
  expect_error(v + "k car\n{\nvisibility 1\n0 1\n", 3, "unterminated '{' of 'k car'");
  expect_error(v + "k car\n{\nvisibility 1\n0 1\nvisibility 1\n0 1\n}\n", 6, "gives 'visibility' twice");
  expect_error(v + "k car\n{\nvisibility 1\n0 1\n}\nk car\n{\nvisibility 1\n0 1\n}\n", 7, "already given");
  expect_error("v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 resolution 8 8\np 3\n", 2, "is missing 'hither'");
  expect_error("v from 0 0 5 at 0 0 5 up 0 1 0 angle 45 hither 1 resolution 8 8\n", 1, "'from' and 'at' coincide");
  expect_error("v from 0 0 5 at 0 0 0 up 0 1 0 angle 0 hither 1 resolution 8 8\n", 1, "view angle");
  expect_error("5\n", 1, "unexpected number '5'");
  std::string deep = v;
  for (int i = 0; i < 1001; ++i) deep += "x a {\n";
  expect_error(deep, 1002, "blocks nested more than 1000 deep");
  // Problems inside an included file name that file.
  expect_error(v + "i 0 sub/part.aff\n", 6, "unknown keyword 'q'", {{"sub/part.aff", std::string(kTri) + "\nq\n"}},
               "sub/part.aff");
  expect_error(v + "i 0 sub/part.aff\n", 1, "'}' without a matching '{'",
               {{"sub/part.aff", "}\n"}}, "sub/part.aff");
}

TEST_CASE("aff: scenes without a view or objects fail", "[aff]") {
  TempDir d;
  const std::string no_view = d.write("nv.aff", kTri);
  try {
    load_scene(no_view);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.problem().find("no view") != std::string::npos);
  }
  CHECK_THROWS_AS(load_scene(d.write("empty.aff", kView)), InputError);
}

TEST_CASE("aff: an include cycle is an error and not a hang", "[aff]") {
  expect_error(std::string(kView) + "i 0 a.aff\n", 1, "include cycle: bad.aff -> a.aff -> b.aff -> a.aff",
               {{"a.aff", "i 0 b.aff\n"}, {"b.aff", "i 0 a.aff\n"}}, "b.aff");
  expect_error(std::string(kView) + "i 0 bad.aff\n", 2, "include cycle");
}

TEST_CASE("aff: every truncation of a valid file loads or fails cleanly", "[aff]") {
  std::ifstream in(kData + "features.aff");
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  REQUIRE(lines.size() > 100);
  TempDir d;
  int ok = 0, failed = 0;
  for (std::size_t n = 0; n <= lines.size(); ++n) {
    std::string text;
    for (std::size_t i = 0; i < n; ++i) text += lines[i] + "\n";
    try {
      load_scene(d.write("cut" + std::to_string(n) + ".aff", text));
      ++ok;
    } catch (const InputError&) {
      ++failed;
    }
  }
  CHECK(ok > 0);
  CHECK(failed > 0);
}

// ----------------------------------------------------------------------------------------
// The real BART scenes (from ../shared; CI always has them)

TEST_CASE("aff: BART kitchen loads with its 110561 triangles and a moving toy car", "[aff][bart]") {
  const std::string path = kBart + "kitchen/kitchen.aff";
  INFO("BART kitchen expected at " << path);
  REQUIRE(fs::exists(path));
  const Scene s = load_scene(path);
  CHECK(s.triangle_count() == 110561);
  CHECK(s.frame_count == 800);
  CHECK(s.width == 800);
  CHECK(s.height == 600);
  CHECK(s.lights.size() == 6);
  for (const Object& o : s.objects) CHECK(o.mesh.triangles.size() <= 4096);

  // The car body: until t = 3 the car holds its first key (4.45, 0, 2.75), turned 180
  // degrees about y; frame 400 is t = 400 x 20 / 799 = 10.01, on its way.
  const Object& car = named(s, "toycar/m10");
  CHECK(car.motion->animated());
  const Affine<double> m0 = car.motion->at(0), m400 = car.motion->at(400);
  CHECK(m0.translation().x == Approx(4.45));
  CHECK(m0.translation().z == Approx(2.75));
  CHECK(m0.m[0][0] == Approx(-1));
  const Vec3d p = car.mesh.vertices[0];
  const Vec3d w0 = m0.point(p), w400 = m400.point(p);
  CHECK(glm::length(w400 - w0) > 0.5);
  CHECK(w400.x > 2.5);  // between the keys at t = 9.8 (2.70, 0, 0.55) and 12 (2.60, 0, 1.50)
  CHECK(w400.x < 2.8);

  // A rear wheel turns relative to the car between two frames.
  const Object& wheel = named(s, "toycar/rotating_wheel_left/m24");
  const Affine<double> inv0 = *inverse(car.motion->at(200)), inv1 = *inverse(car.motion->at(201));
  const Vec3d q = wheel.mesh.vertices[0];
  const Vec3d r0 = inv0.point(wheel.motion->at(200).point(q));
  const Vec3d r1 = inv1.point(wheel.motion->at(201).point(q));
  CHECK(glm::length(r1 - r0) > 1e-6);

  const Camera c0 = s.camera->at(0), c400 = s.camera->at(400);
  CHECK(c0.eye.x == Approx(3.75));  // the camera's key at t = 0
  CHECK(glm::length(c400.eye - c0.eye) > 0.5);
}

TEST_CASE("aff: a rendered BART kitchen frame shows the closed kitchen", "[aff][bart]") {
  const std::string path = kBart + "kitchen/kitchen.aff";
  REQUIRE(fs::exists(path));
  const Scene s = load_scene(path);
  const auto g = build_geometry<float>(s, make_spheres(s, 1));
  const int w = 48, h = 36;
  const FrameResult r = render_reference(s, g, 0, w, h);
  // The kitchen is a room: floor.aff is the plane y = 0 over x in [0, 4.63], z in [0, 4.22];
  // roof.aff the plane y = 2.32 over the same; the window openings of the wall z = 0 go
  // back into it (walls.aff's reveals, windows.aff's frames: less than 0.4); through the panes (glass, transparent in BART, absent here)
  // one sees garden.aff, the plane z = -3.75 over x in [-2, 6], y in [-1.1, 2.9]. At frame
  // 0 the camera (k camera: eye (3.75, 2.3, 3.6)) is inside, looking down into the room:
  // every primary ray hits, in the room or on the garden.
  const Camera cam = s.camera->at(0);
  const CameraRays rays(cam, w, h);
  std::size_t on_floor = 0, on_garden = 0, outside = 0, misses = 0;
  std::set<std::uint32_t> seen;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (r.image.object[i] == 0xFFFFFFFFu) {
        ++misses;
        continue;
      }
      seen.insert(r.image.object[i]);
      const Ray<double> ray = rays.ray<double>(x, y);
      const Vec3d p = ray.o + static_cast<double>(r.image.z[i]) * ray.d;
      const double e = 1e-3;
      const bool in_room = p.x > -e && p.x < 4.63 + e && p.y > -e && p.y < 2.32 + e && p.z > -0.4 && p.z < 4.22 + e;
      const bool garden = std::abs(p.z + 3.75) < e && p.x > -2 - e && p.x < 6 + e && p.y > -1.1 - e && p.y < 2.9 + e;
      outside += !in_room && !garden;
      on_garden += garden;
      on_floor += std::abs(p.y) < e;
    }
  CHECK(misses == 0);
  CHECK(outside == 0);
  CHECK(on_garden > 0);  // the windows are in view
  // Looking down from near the ceiling, the floor fills a good part of the view, and the
  // view holds many distinct objects (furniture, walls, the car...).
  CHECK(on_floor > static_cast<std::size_t>(w * h / 10));
  CHECK(seen.size() >= 10);
}

TEST_CASE("aff: BART museum loads its 1024 flying triangles which move", "[aff][bart]") {
  const std::string path = kBart + "museum/museum5.aff";
  INFO("BART museum expected at " << path);
  REQUIRE(fs::exists(path));
  const Scene s = load_scene(path);
  CHECK(s.frame_count == 300);
  std::size_t flying = 0;
  for (const Object& o : s.objects) {
    if (!o.deform) continue;
    flying += o.mesh.triangles.size();
    std::vector<Vec3d> a, b;
    o.deform->at(0, a);
    o.deform->at(150, b);  // t = -1 + 150 x 6 / 299 = 2.01
    REQUIRE(a.size() == o.mesh.vertices.size());
    REQUIRE(b.size() == a.size());
    CHECK(a == o.mesh.vertices);
    std::size_t moved = 0;
    for (std::size_t i = 0; i < a.size(); ++i) moved += glm::length(b[i] - a[i]) > 1e-3;
    CHECK(moved == a.size());
  }
  CHECK(flying == 1024);
  CHECK(s.triangle_count() > 10000);

  // Vertex normals: only pillar.aff's mesh ("normals 5030", "triangles 10000") has them.
  std::size_t with_normals = 0;
  for (const Object& o : s.objects) with_normals += o.mesh.triangles_with_normals();
  CHECK(with_normals == 10000);
  // Its fm statements' specular colours are 0, 0.3, 0.5 and 0.6 (0.6 0.6 0.4 once); none transmits.
  for (const Material& m : s.materials) {
    CHECK_FALSE(m.transmits());
    CHECK(m.reflect == m.specular);
    CHECK(m.reflect.x <= 0.6);
  }
}

TEST_CASE("aff: the BART kitchen's glass transmits 0.85 with index 1.55", "[aff][bart][materials]") {
  const std::string path = kBart + "kitchen/kitchen.aff";
  REQUIRE(fs::exists(path));
  const Scene s = load_scene(path);
  // param_glass.aff and param_glass_dragon.aff: "fm ... 0.05 0.05 0.05 ... 0.85 1.55", the only
  // statements with T > 0; every other material keeps ior 1.
  std::size_t glass = 0;
  for (const Material& m : s.materials) {
    if (m.transmits()) {
      ++glass;
      CHECK(m.transmit == Vec3d(0.85));
      CHECK(m.ior == 1.55);
      CHECK(m.reflect == Vec3d(0.05));
    } else {
      CHECK(m.ior == 1);
    }
    CHECK(m.reflect == m.specular);
  }
  CHECK(glass == 2);
}

// ----------------------------------------------------------------------------------------
// Materials and vertex normals as published (issue 29, item 2)

namespace {
const Material& material_with_diffuse(const Scene& s, const Vec3d& kd) {
  for (const Material& m : s.materials)
    if (m.diffuse == kd) return m;
  FAIL("no material with that diffuse colour");
  throw std::logic_error("unreachable");
}
}  // namespace

TEST_CASE("aff: f and fm keep their reflection weight, transmittance and index", "[aff][materials]") {
  TempDir d;
  // f: colour 1 0.5 0.25, Kd 0.8, Ks 0.3, Shine 20, T 0.5, index 1.5.
  // fm: ambient 0.1, diffuse 0.5, specular 0.2 0.3 0.4, Shine 40, T 0, index 0 (BART writes 0).
  // fm: diffuse 0.25, specular 0, T 0.9, index 1.33: transmits without reflecting.
  const std::string text = std::string(kView) + "f 1 0.5 0.25 0.8 0.3 20 0.5 1.5\n" + kTri +
                           "fm 0.1 0.1 0.1 0.5 0.5 0.5 0.2 0.3 0.4 40 0 0\n" + kTri +
                           "fm 0 0 0 0.25 0.25 0.25 0 0 0 1 0.9 1.33\n" + kTri;
  const Scene s = load_scene(d.write("m.aff", text));
  REQUIRE(s.materials.size() == 3);
  const Material& f = material_with_diffuse(s, Vec3d(0.8, 0.4, 0.2));
  CHECK(f.specular == Vec3d(0.3));  // unchanged: Ks x white
  CHECK(f.shininess == 20);
  CHECK(f.reflect == Vec3d(0.3));  // BART: Ks is also the reflection weight
  CHECK(f.transmit == Vec3d(0.5));
  CHECK(f.ior == 1.5);
  const Material& fm = material_with_diffuse(s, Vec3d(0.5));
  CHECK(fm.specular == Vec3d(0.2, 0.3, 0.4));
  CHECK(fm.reflect == Vec3d(0.2, 0.3, 0.4));
  CHECK(fm.transmit == Vec3d(0));
  CHECK(fm.ior == 1);  // T = 0: the written 0 is no index
  CHECK_FALSE(fm.transmits());
  const Material& glass = material_with_diffuse(s, Vec3d(0.25));
  CHECK_FALSE(glass.reflects());
  CHECK(glass.transmit == Vec3d(0.9));
  CHECK(glass.ior == 1.33);
  CHECK(has_note(s, "transmittance with index of refraction read: traced as reflection and refraction rays"));
}

TEST_CASE("aff: pp normals follow a non-uniform static scale by the inverse transpose", "[aff][normals]") {
  TempDir d;
  // Written normal (1, 1, 0) under xs scale (2, 1, 1): the inverse transpose diag(1/2, 1, 1)
  // maps it to (1/2, 1, 0), renormalised (1, 2, 0) / sqrt(5). The normal (0, 0, 3) is (0, 0, 1).
  const std::string text = std::string(kView) + "fm 0 0 0 1 1 1 0 0 0 0 0 0\n" +
                           "xs 2 1 1  0 0 1 0  0 0 0 {\n"
                           "pp 4\n0 0 0 1 1 0\n1 0 0 1 1 0\n1 1 0 1 1 0\n0 1 0 0 0 3\n}\n";
  const Scene s = load_scene(d.write("pp.aff", text));
  REQUIRE(s.objects.size() == 1);
  const Mesh& m = s.objects[0].mesh;
  REQUIRE(m.triangles.size() == 2);
  REQUIRE(m.normal_index.size() == 2);
  CHECK(m.triangles_with_normals() == 2);
  CHECK(m.vertices[m.triangles[0][1]] == Vec3d(2, 0, 0));  // the vertex is scaled
  const double r5 = std::sqrt(5.0);
  for (int k = 0; k < 3; ++k) {
    const Vec3d n = m.normals[m.normal_index[0][k]];
    CHECK(n.x == Approx(1 / r5).epsilon(1e-15));
    CHECK(n.y == Approx(2 / r5).epsilon(1e-15));
    CHECK(n.z == 0);
  }
  // Fan (0, 2, 3): corner 2 is the fourth vertex with (0, 0, 3).
  CHECK(m.normals[m.normal_index[1][2]] == Vec3d(0, 0, 1));
  CHECK(has_note(s, "vertex normals read"));
  CHECK_FALSE(has_note(s, "vertex normals ignored"));
}

TEST_CASE("aff: mesh normals are per corner and flat triangles join the same group", "[aff][normals]") {
  TempDir d;
  // A flat triangle first, then a mesh whose vertex 0 has normal 0 in triangle 0 and normal
  // 1 in triangle 1 (a crease), BART's order: three vertex indices, then three normal indices.
  const std::string text = std::string(kView) + "fm 0 0 0 1 1 1 0 0 0 0 0 0\n" + kTri +
                           "m vertices 4 0 0 0 1 0 0 1 1 0 0 1 0\n"
                           "normals 2 0 0 1 0 2 0\n"
                           "triangles 2\n0 1 2 0 0 0\n0 2 3 1 1 1\n";
  const Scene s = load_scene(d.write("m.aff", text));
  REQUIRE(s.objects.size() == 1);
  const Mesh& m = s.objects[0].mesh;
  REQUIRE(m.triangles.size() == 3);
  REQUIRE(m.normal_index.size() == 3);
  CHECK_FALSE(m.has_normals(0));  // the `p` triangle
  CHECK(m.normal_index[0] == Tri{kNoNormal, kNoNormal, kNoNormal});
  CHECK(m.triangles_with_normals() == 2);
  CHECK(m.vertices.size() == 3 + 4);  // vertices are not split by their normals
  for (int k = 0; k < 3; ++k) {
    CHECK(m.normals[m.normal_index[1][k]] == Vec3d(0, 0, 1));
    CHECK(m.normals[m.normal_index[2][k]] == Vec3d(0, 1, 0));  // (0, 2, 0) made unit
  }
  CHECK(m.triangles[1][0] == m.triangles[2][0]);  // one vertex, two normals
}

TEST_CASE("aff: a zero normal leaves its triangle flat and tpa normals stay ignored", "[aff][normals]") {
  TempDir d;
  const std::string text = std::string(kView) + "fm 0 0 0 1 1 1 0 0 0 0 0 0\n" +
                           "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n"
                           "tpa 1\n0 0 0 0 0 0 1 1 0 0 0 0 1 0 1 0 0 0 1\n";
  const Scene s = load_scene(d.write("z.aff", text));
  std::size_t with = 0, all = 0;
  for (const Object& o : s.objects) {
    with += o.mesh.triangles_with_normals();
    all += o.mesh.triangles.size();
    if (o.deform) CHECK(o.mesh.normal_index.empty());
  }
  CHECK(all == 2);
  CHECK(with == 0);
  CHECK(has_note(s, "1 triangles with a zero-length vertex normal: shaded flat"));
  CHECK(has_note(s, "vertex normals of animated triangles ('tpa') ignored"));
}

TEST_CASE("aff: split parts keep each triangle's own normals", "[aff][normals]") {
  // 40 patches along x, each with the normal (x, 0, 1) at every corner, split into parts of at
  // most 8: every part's triangles still point at their own normals.
  TempDir d;
  std::string text = std::string(kView) + "fm 0 0 0 1 1 1 0 0 0 0 0 0\n";
  for (int i = 0; i < 40; ++i) {
    const std::string x = std::to_string((i * 17) % 40), n = x + " 0 1";
    text += "pp 3\n" + x + " 0 0 " + n + "\n" + x + ".5 0 0 " + n + "\n" + x + " 1 0 " + n + "\n";
  }
  AffOptions opt;
  opt.max_object_triangles = 8;
  const Scene s = load_aff(d.write("split.aff", text), opt);
  REQUIRE(s.objects.size() == 8);
  std::size_t checked = 0;
  for (const Object& o : s.objects) {
    const Mesh& m = o.mesh;
    REQUIRE(m.normal_index.size() == m.triangles.size());
    CHECK(m.normals.size() == 3 * m.triangles.size());  // only the normals it uses
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const double x = std::floor(m.vertices[m.triangles[t][k]].x);
        const Vec3d want = Vec3d(x, 0, 1) / std::sqrt(x * x + 1);
        const Vec3d got = m.normals[m.normal_index[t][k]];
        CHECK(glm::length(got - want) < 1e-15);
        ++checked;
      }
  }
  CHECK(checked == 120);
}
