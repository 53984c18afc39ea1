// BART's tolerances (issue 15): key lists whose times go backwards or repeat load with one
// warning, and move as BART's reference code (kbsplpos.c, kbsplrot.c: KB_PosInterpolate,
// KB_RotInterpolate; animation.c: _GetVisibility; viGetAnimatedTriangle) moves them. Every
// expected value below is worked out by hand from those rules, in the comment beside it.
#include "scene/aff.h"
#include "base/error.h"
#include "scene/kb_spline.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

using namespace oprt;

namespace {
namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

struct TempDir {
  fs::path dir;
  TempDir() {
    static int n = 0;
    dir = fs::temp_directory_path() / ("oprt_aff_quirks_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
    fs::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir / name;
    std::ofstream(p) << text;
    return p.lexically_normal().string();
  }
};

const char* kView = "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 0.1 resolution 8 8\n";

// x = values[i] at times[i], zero tension, continuity and bias.
KbVecSpline line_keys(const std::vector<double>& times, const std::vector<double>& values) {
  std::vector<KbVecKey> k;
  for (std::size_t i = 0; i < times.size(); ++i) k.push_back({times[i], {values[i], 0, 0}, {}});
  return KbVecSpline(k);
}

// The angle (degrees, in [0, 360)) of a rotation about +z.
double z_angle(const Quatd& q) {
  const Affine<double> r = rotation_matrix(q);
  const double a = std::atan2(r.m[1][0], r.m[0][0]) * 180 / kPi;
  return a < 0 ? a + 360 : a;
}

KbRotSpline z_keys(const std::vector<double>& times, const std::vector<double>& degrees) {
  std::vector<KbRotKey> k;
  for (std::size_t i = 0; i < times.size(); ++i) k.push_back({times[i], {0, 0, 1}, degrees[i], {}});
  return KbRotSpline(k);
}
}  // namespace

TEST_CASE("kb: a key list that starts again uses the first segment ending after t", "[aff][kb][bart]") {
  // As BART's robots write a spinning gun: keys at t = 0 .. 10 with x = t, then the list
  // starts again at t = 6 .. 12 with x = 100 + t. Segments (t1, t2) run (1,2) .. (9,10),
  // (10,6), (6,7) .. (10,11); k at t = 12 only shapes the end. For t < 10 the first part
  // has the first segment ending after t; from t = 10 on only the restarted part's (10, 11).
  const std::vector<double> t = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 6, 7, 8, 9, 10, 11, 12};
  std::vector<double> x;
  for (std::size_t i = 0; i < t.size(); ++i) x.push_back(i < 11 ? t[i] : 100 + t[i]);
  const KbVecSpline s = line_keys(t, x);
  // Catmull-Rom on evenly spaced points of a line is the line.
  CHECK(s.at(5.5).x == Approx(5.5));
  CHECK(s.at(10).x == Approx(110));  // segment (10, 11) at u = 0: the restarted key
  CHECK(s.at(10.5).x == Approx(110.5));
  // Segment (9, 10) has the restart's first key (t = 6, x = 106) as its outer neighbour:
  // a1 = 2 (10 - 9) / (10 - 8) = 1, a2 = 2 (10 - 9) / (6 - 9) = -2/3, so Tout = 1 and
  // Tin = -1/3 (10 - 9) - 1/3 (106 - 10) = -97/3; c2 = 3 - 2 + 97/3 = 100/3, c3 = -100/3;
  // at u = 1/2: 9 + 1/2 + 100/12 - 100/24 = 9.5 + 25/6.
  CHECK(s.at(9.5).x == Approx(9.5 + 25.0 / 6));
  // At or before the first segment's start (t = 1) the curve holds that key; at or after
  // the last segment's end (t = 11) it holds that one.
  CHECK(s.at(1).x == Approx(1));
  CHECK(s.at(-3).x == Approx(1));
  CHECK(s.at(11).x == Approx(111));
  CHECK(s.at(50).x == Approx(111));
  for (double u = -2; u <= 14; u += 0.0625) CHECK(std::isfinite(s.at(u).x));
}

TEST_CASE("kb: a repeated time inside the curve is a jump with BART's tangents", "[aff][kb][bart]") {
  // x = 0 1 2 3 | 13 14 15 16 at t = 0 1 2 3 | 3 4 5 6: segments (1,2) (2,3) (3,3) (3,4) (4,5).
  const KbVecSpline s = line_keys({0, 1, 2, 3, 3, 4, 5, 6}, {0, 1, 2, 3, 13, 14, 15, 16});
  // Segment (2, 3) sees the jump through its outer key (t = 3, x = 13): a1 = 2/2 = 1,
  // a2 = 2 / (3 - 2) = 2: Tout = 1, Tin = 1 + 10 = 11, c2 = 3 - 2 - 11 = -10, c3 = 10;
  // at u = 1/2: 2 + 0.5 - 2.5 + 1.25.
  CHECK(s.at(2.5).x == Approx(1.25));
  CHECK(s.at(3 - 1e-9).x == Approx(3).margin(1e-6));
  CHECK(s.at(3).x == Approx(13));  // (3, 3) is never entered: (3, 4) at u = 0
  // Segment (3, 4): a1 = 2 / (4 - 3) = 2, a2 = 2 / (5 - 3) = 1: Tout = (13 - 3) + 1 = 11,
  // Tin = 1, c2 = 3 - 22 - 1 = -20, c3 = -2 + 11 + 1 = 10; at u = 1/2: 13 + 5.5 - 5 + 1.25.
  CHECK(s.at(3.5).x == Approx(14.75));
  CHECK(s.at(0.5).x == Approx(1));  // before the first segment's start
  CHECK(s.at(7).x == Approx(15));   // after the last segment's end (t = 5)
}

TEST_CASE("kb: a rotation list that starts again turns as BART turns it", "[aff][kb][bart]") {
  // About z, 90 degrees per time unit: 0 90 180 270 360 at t = 0..4, then again from t = 2:
  // 360 450 540 630 720 at t = 2..6. Every key's quaternion is in its predecessor's
  // hemisphere, so no key is flipped, and equal steps give equal logarithms L (45 degrees
  // about z, half the step).
  const KbRotSpline s = z_keys({0, 1, 2, 3, 4, 2, 3, 4, 5, 6}, {0, 90, 180, 270, 360, 360, 450, 540, 630, 720});
  // Segments of constant rate: the tangents are L and squad is the slerp.
  CHECK(z_angle(s.at(1.5)) == Approx(135));
  CHECK(z_angle(s.at(4.5)) == Approx(225));  // the restarted part's segment (4, 5)
  // Segment (3, 4) has the restart's key at t = 2 as its outer neighbour: a1 = 2 / (4 - 2)
  // = 1 and a2 = 2 / (2 - 3) = -2, so Tout = L, Tin = -L - log(q(360)^-1 q(360)) = -L;
  // a = q1, b = q2 exp(L) = 450 degrees. At u = 1/2: slerp(270, 360) = 315,
  // slerp(270, 450) = 360, and squad = slerp(315, 360, 2u(1-u) = 1/2) = 337.5.
  CHECK(z_angle(s.at(3.5)) == Approx(337.5));
  CHECK(z_angle(s.at(-1)) == Approx(90));  // holds the first segment's start
  CHECK(z_angle(s.at(9)) == Approx(270));  // holds the last segment's end (630 degrees)
}

TEST_CASE("kb: where BART divides by zero the tangent weight is 0", "[aff][kb][bart]") {
  // Segment (1, 2) with its outer keys at t = 2 and t = 1: BART's a1 = 2 / (2 - 2) and
  // a2 = 2 / (1 - 1) are infinite (its curve is NaN there); here both are 0, so the
  // segment is the cubic 1 + (3u^2 - 2u^3): 1.5 at u = 1/2.
  const KbVecSpline s = line_keys({2, 1, 2, 1}, {7, 1, 2, 9});
  CHECK(s.at(1.5).x == Approx(1.5));
  CHECK(s.at(1.25).x == Approx(1 + 3 * 0.0625 - 2 * 0.015625));
}

TEST_CASE("kb: quirks are named by the first key of each kind", "[aff][kb][bart]") {
  CHECK(kb_time_quirks({0, 1, 2, 3}).backwards == 0);
  // BART's idiom: the first and last keys repeat their neighbours' times. Not a quirk.
  KbTimeQuirks q = kb_time_quirks({0, 0, 1, 2, 2});
  CHECK(q.backwards == 0);
  CHECK(q.repeat == 0);
  q = kb_time_quirks({0, 1, 1, 2, 3, 2, 2, 4});
  CHECK(q.repeat == 2);
  CHECK(q.backwards == 5);
  CHECK(kb_time_quirks({1, 0, 2, 3}).backwards == 1);  // the first key goes backwards: still reported
}

TEST_CASE("aff: a list that goes backwards and repeats loads with one warning naming file and line",
          "[aff][bart]") {
  TempDir d;
  // `a 0 6 7`: frame f is time f. The gun's rotation runs 0..4 and starts again at 2..6 (the
  // list of kb test above); its translation repeats a time inside the curve.
  const std::string gun =
      "x gun\n{\np 3\n0 0 0\n1 0 0\n0 1 0\n}\n"
      "k gun\n{\n"
      "rot 10\n"
      "0 0 0 1 0 0 0 0\n1 0 0 1 90 0 0 0\n2 0 0 1 180 0 0 0\n3 0 0 1 270 0 0 0\n4 0 0 1 360 0 0 0\n"
      "2 0 0 1 360 0 0 0\n3 0 0 1 450 0 0 0\n4 0 0 1 540 0 0 0\n5 0 0 1 630 0 0 0\n6 0 0 1 720 0 0 0\n"
      "transl 6\n0 0 0 0 0 0 0\n1 1 0 0 0 0 0\n2 2 0 0 0 0 0\n2 5 0 0 0 0 0\n3 6 0 0 0 0 0\n4 7 0 0 0 0 0\n"
      "}\n";
  d.write("gun.aff", gun);
  // The gun is included twice (as BART's kitchen includes its rear-wheel file twice): its
  // lists are one definition, and each quirk is said once.
  const std::string root = d.write("root.aff", std::string(kView) + "a 0 6 7\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n" +
                                                   "i 0 gun.aff\nxs 1 1 1 0 0 1 0 3 0 0\n{\ni 0 gun.aff\n}\n");
  LoadOptions quiet;
  quiet.print_warnings = false;
  const Scene s = load_scene(root, quiet);
  const std::string file = (d.dir / "gun.aff").lexically_normal().string();
  REQUIRE(s.warnings.size() == 2);
  CHECK(s.warnings[0].rfind(file + ": line 10: 'rot' keys of 'k gun': times go backwards: key 6 of 10 (line 16) "
                                   "at time 2 after 4",
                            0) == 0);
  CHECK(s.warnings[1].rfind(file + ": line 21: 'transl' keys of 'k gun': a time repeats: key 4 of 6 (line 25) "
                                   "at time 2",
                            0) == 0);
  for (const std::string& w : s.warnings) CHECK(w.find("as BART reads them") != std::string::npos);
  // It moves as the splines above: at frame 3.5 the rotation is 337.5 degrees and the
  // translation is on segment (2, 3) after the jump at t = 2.
  const Object& o = s.objects.at(0);
  const Affine<double> m = o.motion->at(3.5);
  const double deg = std::atan2(m.m[1][0], m.m[0][0]) * 180 / kPi;
  CHECK(deg + 360 == Approx(337.5));
  CHECK(o.motion->at(2).translation().x == Approx(5));
  CHECK(o.motion->at(1.999999).translation().x == Approx(2).margin(1e-4));
}

TEST_CASE("aff: visibility keys out of order are walked as BART walks them", "[aff][bart]") {
  // Keys (t 5: hidden), (t 3: shown), (t 8: hidden), frame f = time f. BART's _GetVisibility
  // goes through the list as written: before 5, visible (the default before the first key);
  // from 5 on it passes key 1, then stops at key 2 (t >= 3 and t < 8), giving key 2's flag
  // (shown); from 8 on the last key's (hidden). Sorting the keys would hide frames 5..7.
  TempDir d;
  const std::string path = d.write("blink.aff", std::string(kView) +
                                                    "a 0 10 11\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n"
                                                    "x blink\n{\np 3\n0 0 0\n1 0 0\n0 1 0\n}\n"
                                                    "k blink\n{\nvisibility 3\n5 0\n3 1\n8 0\n}\n");
  LoadOptions quiet;
  quiet.print_warnings = false;
  const Scene s = load_scene(path, quiet);
  const Motion& m = *s.objects.at(0).motion;
  for (int f = 0; f <= 10; ++f) {
    INFO("frame " << f);
    CHECK(m.visible(f) == (f < 8));
  }
  REQUIRE(s.warnings.size() == 1);
  CHECK(s.warnings[0].find("line 14: 'visibility' keys of 'k blink': times go backwards: key 2 of 3 (line 16) "
                           "at time 3 after 5") != std::string::npos);
}

TEST_CASE("aff: tpa keys out of order interpolate to the first key later than t", "[aff][bart]") {
  // One tpa triangle whose x offset is 0, 20, 10, 30 at t = 0, 2, 1, 3 (frame f = time f / 2).
  // BART's viGetAnimatedTriangle: at t = 1.5 the first key later than t is key 2 (t = 2):
  // from key 1 (t 0) at (1.5 - 0) / 2 = 0.75, x = 15. At t = 2.5 it is key 4 (t = 3): from
  // key 3 (t 1, x 10) at 0.75, x = 25.
  auto key = [](int t, int x) {  // the triangle (0 0 0) (1 0 0) (0 1 0) moved by x, normals +z
    const std::string a = std::to_string(x), b = std::to_string(x + 1);
    return std::to_string(t) + "\n" + a + " 0 0 0 0 1\n" + b + " 0 0 0 0 1\n" + a + " 1 0 0 0 1\n";
  };
  TempDir d;
  const std::string path = d.write("fly.aff", std::string(kView) + "a 0 3 7\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n" +
                                                  "tpa 4\n" + key(0, 0) + key(2, 20) + key(1, 10) + key(3, 30) +
                                                  "tpa 2\n" + key(1, 0) + key(0, 5));
  LoadOptions quiet;
  quiet.print_warnings = false;
  const Scene s = load_scene(path, quiet);
  const Object& o = s.objects.at(0);
  REQUIRE(o.deform);
  std::vector<Vec3d> v;
  o.deform->at(3, v);  // t = 1.5
  CHECK(v.at(0).x == Approx(15));
  o.deform->at(5, v);  // t = 2.5
  CHECK(v.at(0).x == Approx(25));
  o.deform->at(6, v);  // t = 3: the last key
  CHECK(v.at(0).x == Approx(30));
  REQUIRE(s.warnings.size() == 1);
  // One warning for the file, naming the first such 'tpa' and counting the others.
  CHECK(s.warnings[0].find("line 5: 'tpa' key times go backwards: key 3 of 4 (line 14) at time 1 after 2 "
                           "(and in 1 more 'tpa' of this file)") != std::string::npos);
}
