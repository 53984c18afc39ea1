#include "scene/motion.h"
#include "scene/scene.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
KeyframeMotion two_keys() {
  RigidKey a, b;
  a.frame = 10;
  a.translate = {0, 0, 0};
  a.rotate = axis_angle({0, 0, 1}, 0);
  a.scale = 1;
  b.frame = 20;
  b.translate = {10, 0, 0};
  b.rotate = axis_angle({0, 0, 1}, 90);
  b.scale = 3;
  return KeyframeMotion({a, b});
}
}  // namespace

TEST_CASE("motion: at the keys - between them - and clamped outside", "[motion]") {
  const KeyframeMotion m = two_keys();
  // At frame 20: scale 3, rotate 90 about z, translate 10: (1,0,0) -> (3,0,0) -> (0,3,0) -> (10,3,0).
  Vec3d p = m.at(20).point({1, 0, 0});
  CHECK(p.x == Approx(10));
  CHECK(p.y == Approx(3));
  // Halfway: translate 5, scale 2, rotate 45 (slerp): (1,0,0) -> (sqrt2, sqrt2, 0) + (5,0,0).
  p = m.at(15).point({1, 0, 0});
  CHECK(p.x == Approx(5 + std::sqrt(2.0)));
  CHECK(p.y == Approx(std::sqrt(2.0)));
  // A quarter: rotation 22.5 degrees (slerp is uniform in angle), scale 1.5.
  p = m.at(12.5).point({1, 0, 0});
  CHECK(std::atan2(p.y, p.x - 2.5) == Approx(22.5 * 3.14159265358979323846 / 180));
  // Outside the keys the motion holds.
  CHECK(m.at(0).point({1, 0, 0}).x == Approx(1));
  CHECK(m.at(100).point({1, 0, 0}).y == Approx(3));
}

TEST_CASE("motion: slerp takes the short way round", "[motion]") {
  RigidKey a, b;
  a.frame = 0;
  a.rotate = axis_angle({0, 1, 0}, 170);
  b.frame = 1;
  b.rotate = axis_angle({0, 1, 0}, -170);  // 20 degrees away, across 180
  const KeyframeMotion m({a, b});
  const Vec3d p = m.at(0.5).point({1, 0, 0});  // expect 180 degrees: (-1, 0, 0)
  CHECK(p.x == Approx(-1));
  CHECK(p.z == Approx(0).margin(1e-12));
}

TEST_CASE("camera: keyframed camera interpolates eye and target", "[motion]") {
  CameraKey a, b;
  a.frame = 0;
  a.camera.eye = {0, 0, 10};
  b.frame = 4;
  b.camera.eye = {4, 0, 10};
  b.camera.target = {4, 0, 0};
  const KeyframeCamera c({a, b});
  CHECK(c.at(1).eye.x == Approx(1));
  CHECK(c.at(1).target.x == Approx(1));
  CHECK(c.at(9).eye.x == Approx(4));
}

TEST_CASE("motion: keys more than half a turn apart interpolate along the shorter arc", "[motion]") {
  // Keys at 0 and 270 degrees about z: 270 degrees one way, 90 the other. The rotations are
  // the same as 0 and -90, so a third of the way is -30 degrees: (1,0,0) -> (cos 30, -sin 30, 0).
  // The long way round would give +90 degrees, (0, 1, 0). The quaternions of the two keys
  // (cos 0, sin 0 z) and (cos 135, sin 135 z) have a negative dot product: the second one
  // stands for the same rotation negated, which is what takes the short way.
  RigidKey a, b;
  a.frame = 0;
  a.rotate = axis_angle({0, 0, 1}, 0);
  b.frame = 3;
  b.rotate = axis_angle({0, 0, 1}, 270);
  REQUIRE(glm::dot(a.rotate, b.rotate) < 0);
  const KeyframeMotion m({a, b});
  Vec3d p = m.at(1).point({1, 0, 0});
  CHECK(p.x == Approx(std::sqrt(3.0) / 2));
  CHECK(p.y == Approx(-0.5));
  CHECK(p.z == Approx(0).margin(1e-12));
  // Two thirds: -60 degrees; at the second key exactly its own rotation, 270 = -90.
  p = m.at(2).point({1, 0, 0});
  CHECK(p.x == Approx(0.5));
  CHECK(p.y == Approx(-std::sqrt(3.0) / 2));
  p = m.at(3).point({1, 0, 0});
  CHECK(p.x == Approx(0).margin(1e-12));
  CHECK(p.y == Approx(-1));
  // Keys 200 degrees apart about x (10 and 210): the short way is -160 degrees, so halfway
  // is 10 - 80 = -70 degrees: (0,1,0) -> (0, cos -70, sin -70).
  a.rotate = axis_angle({1, 0, 0}, 10);
  b.rotate = axis_angle({1, 0, 0}, 210);
  b.frame = 2;
  const KeyframeMotion x({a, b});
  p = x.at(1).point({0, 1, 0});
  const double r = -70 * 3.14159265358979323846 / 180;
  CHECK(p.x == Approx(0).margin(1e-12));
  CHECK(p.y == Approx(std::cos(r)));
  CHECK(p.z == Approx(std::sin(r)));
}
