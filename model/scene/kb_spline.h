// Kochanek-Bartels (TCB) splines, evaluated the way BART's reference code (kbsplpos.c,
// kbsplrot.c, after D. Eberly) evaluates them, so that a BART scene moves here as it moves
// in the benchmark:
//
// - Keys k_0 .. k_{n-1} (n >= 4) at non-decreasing times. The first and the last key only
//   shape the end tangents: the curve runs from k_1 (at t_1) to k_{n-2} (at t_{n-2}), one
//   cubic segment per pair of neighbouring keys, and holds (clamps) outside that range.
// - Segment i joins P1 = k_{i+1} and P2 = k_{i+2}, with P0, P3 their outer neighbours, as a
//   cubic Hermite curve in u = (t - t1) / (t2 - t1) in [0, 1]:
//       P(u) = P1 + Tout u + (3D - 2Tout - Tin) u^2 + (-2D + Tout + Tin) u^3,  D = P2 - P1.
//   With the key's tension T, continuity C and bias B:
//       Tout = a1 (1-T1)(1+C1)(1+B1)/2 (P1 - P0) + a1 (1-T1)(1-C1)(1-B1)/2 D
//       Tin  = a2 (1-T2)(1-C2)(1+B2)/2 D         + a2 (1-T2)(1+C2)(1-B2)/2 (P3 - P2)
//   where a1 = 2 (t2 - t1) / (t2 - t0) and a2 = 2 (t2 - t1) / (t3 - t1) rescale the
//   tangents for unevenly spaced keys (both are 1 for even spacing). T = C = B = 0 with
//   even spacing is the Catmull-Rom spline.
// - A segment of zero length (two keys at the same time, as in BART's kitchen wheels) is
//   never entered: the curve jumps there from one key to the next. Its coefficients are
//   kept finite (zero tangents) so that nothing downstream sees a NaN.
//
// Rotations use the same tangents on unit quaternions (logarithms of the relative
// rotations instead of differences) and spherical quadrangle interpolation (squad) with
// the inner control points a = q1 exp((Tout - log(q1^-1 q2)) / 2) and
// b = q2 exp((log(q1^-1 q2) - Tin) / 2). Each key is an axis (normalised here) and an
// angle; consecutive quaternions are put in the same hemisphere first, so a step between
// two keys always takes the shorter way (below 180 degrees), as BART does. One deliberate
// difference: BART flips the keys one segment at a time and so computes the incoming
// tangent of a segment from an unflipped k_{i+3}; here every key is flipped up front. The
// two agree unless two consecutive keys are more than 180 degrees apart.
#pragma once

#include "scene/motion.h"

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

// Throws std::invalid_argument for fewer than 4 keys, decreasing times, or non-finite data.
class KbVecSpline {
 public:
  explicit KbVecSpline(const std::vector<KbVecKey>& keys);
  Vec3d at(double t) const;
  double start() const { return segs_.front().t1; }  // t_1: before it the curve holds
  double end() const { return segs_.back().t2; }     // t_{n-2}: after it the curve holds

 private:
  struct Segment {
    double t1, t2;
    Vec3d c0, c1, c2, c3;  // P(u) = c0 + u (c1 + u (c2 + u c3))
  };
  std::vector<Segment> segs_;
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
};

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
