// Kochanek-Bartels (TCB) splines, evaluated the way BART's reference code (kbsplpos.c,
// kbsplrot.c, after D. Eberly: KB_PosInterpolate, KB_RotInterpolate) evaluates them, so that
// a BART scene moves here as it moves in the benchmark, even where its key times go
// backwards or repeat:
//
// - Keys k_0 .. k_{n-1} (n >= 4), in the order written, at any times. The first and the last
//   key only shape the end tangents: segment i (i = 0 .. n-4) joins P1 = k_{i+1} (at t1) and
//   P2 = k_{i+2} (at t2), with P0, P3 their outer neighbours, as a cubic Hermite curve in
//   u = (t - t1) / (t2 - t1):
//       P(u) = P1 + Tout u + (3D - 2Tout - Tin) u^2 + (-2D + Tout + Tin) u^3,  D = P2 - P1.
//   With the key's tension T, continuity C and bias B:
//       Tout = a1 (1-T1)(1+C1)(1+B1)/2 (P1 - P0) + a1 (1-T1)(1-C1)(1-B1)/2 D
//       Tin  = a2 (1-T2)(1-C2)(1+B2)/2 D         + a2 (1-T2)(1+C2)(1-B2)/2 (P3 - P2)
//   where a1 = 2 (t2 - t1) / (t2 - t0) and a2 = 2 (t2 - t1) / (t3 - t1) rescale the
//   tangents for unevenly spaced keys (both are 1 for even spacing). T = C = B = 0 with
//   even spacing is the Catmull-Rom spline. Out-of-order times make a1 or a2 negative,
//   as they do in BART; where BART would divide by zero (t2 - t0 = 0 or t3 - t1 = 0 with
//   t2 != t1) its curve is NaN, and here the weight is 0 instead.
// - Which segment (BART's rule): for t at or before the first segment's start t_1 the curve
//   holds k_1 (segment 0 at u = 0); for t at or after the last segment's end t_{n-2} it
//   holds k_{n-2} (the last segment at u = 1); otherwise it is segment i, the first whose end
//   time exceeds t. That segment starts at or before t (the one before it ended at or before
//   t), so 0 <= u < 1: a segment of zero length (two keys at one time, as in BART's kitchen
//   wheels) or running backwards (a list that starts again, as in BART's robots) is never
//   entered, and the curve jumps where such a segment would be.
//
// Rotations use the same tangents on unit quaternions (logarithms of the relative
// rotations instead of differences) and spherical quadrangle interpolation (squad) with
// the inner control points a = q1 exp((Tout - log(q1^-1 q2)) / 2) and
// b = q2 exp((log(q1^-1 q2) - Tin) / 2). Each key is an axis (normalised here) and an
// angle. Like BART, segment i puts q2 in q1's hemisphere (so a step between two keys takes
// the shorter way) and keeps that sign for the later segments; q0 and q1 are the keys as
// signed by the segments before (k_0 and k_1 as written), and q3 is k_{i+3} as written.
#pragma once

#include "scene/motion.h"

#include <cstddef>
#include <vector>

namespace oprt {

struct KbParams {
  double tension = 0, continuity = 0, bias = 0;
};

struct KbVecKey {
  double t = 0;
  Vec3d value{0};
  KbParams tcb;
};

struct KbRotKey {
  double t = 0;
  Vec3d axis{1, 0, 0};  // need not be unit; must be non-zero unless the angle is zero
  double degrees = 0;
  KbParams tcb;
};

// Throws std::invalid_argument for fewer than 4 keys or non-finite data. Key times need not
// increase (see above); the loader warns where they do not.
class KbVecSpline {
 public:
  explicit KbVecSpline(const std::vector<KbVecKey>& keys);
  Vec3d at(double t) const;
  double start() const { return segs_.front().t1; }  // t_1: at or before it the curve holds
  double end() const { return segs_.back().t2; }     // t_{n-2}: at or after it the curve holds

 private:
  struct Segment {
    double t1, t2;
    Vec3d c0, c1, c2, c3;  // P(u) = c0 + u (c1 + u (c2 + u c3))
  };
  std::vector<Segment> segs_;
  std::vector<double> reach_;  // reach_[i]: the latest end time of segments 0 .. i
};

class KbRotSpline {
 public:
  explicit KbRotSpline(const std::vector<KbRotKey>& keys);
  Quatd at(double t) const;  // unit quaternion
  double start() const { return segs_.front().t1; }
  double end() const { return segs_.back().t2; }

 private:
  struct Segment {
    double t1, t2;
    Quatd p, a, b, q;  // squad(u) = slerp(slerp(p, q, u), slerp(a, b, u), 2u(1-u))
  };
  std::vector<Segment> segs_;
  std::vector<double> reach_;
};

// BART's rule for key times that do not increase, named for warnings: the index of the
// first key whose time is below its predecessor's (backwards), and of the first key among
// k_1 .. k_{n-2} at the same time as its predecessor there (a repeat inside the curve: a
// jump). A repeat involving k_0 or k_{n-1}, which only shape the end tangents, is BART's
// common way to write a list and is not reported. 0: none. The counts say how many keys
// of each kind there are.
struct KbTimeQuirks {
  std::size_t backwards = 0, repeat = 0;
  std::size_t backwards_count = 0, repeat_count = 0;
};
KbTimeQuirks kb_time_quirks(const std::vector<double>& times);

// Unit-quaternion helpers (exposed for tests). log and exp map between unit quaternions
// and pure quaternions (w = 0) whose vector part is half the rotation angle times the axis.
// slerp never flips its second argument: the caller chooses the hemisphere.
Quatd quat_log(const Quatd& q);
Quatd quat_exp(const Quatd& v);
Quatd quat_slerp(const Quatd& p, const Quatd& q, double u);
Quatd quat_squad(const Quatd& p, const Quatd& a, const Quatd& b, const Quatd& q, double u);

// Rotation matrix of a unit quaternion, as the linear part of an affine map.
Affine<double> rotation_matrix(const Quatd& q);

}  // namespace oprt
