#include "scene/kb_spline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace oprt {

namespace {

struct Tangents {
  double out_prev, out_next;  // Tout = out_prev (P1 - P0) + out_next (P2 - P1)
  double in_prev, in_next;    // Tin  = in_prev (P2 - P1) + in_next (P3 - P2)
};

// The four TCB weights of segment t1..t2 with outer keys at t0 and t3 (see the header),
// as BART computes them whatever the order of the times; a weight BART would divide by zero
// for (its curve would be NaN there) is 0.
double rescale(double t1, double t2, double span) {
  const double a = 2 * (t2 - t1) / span;
  return std::isfinite(a) ? a : 0.0;
}

Tangents tcb_weights(double t0, double t1, double t2, double t3, const KbParams& k1, const KbParams& k2) {
  const double a1 = rescale(t1, t2, t2 - t0);
  const double a2 = rescale(t1, t2, t3 - t1);
  Tangents w;
  w.out_prev = 0.5 * a1 * (1 - k1.tension) * (1 + k1.continuity) * (1 + k1.bias);
  w.out_next = 0.5 * a1 * (1 - k1.tension) * (1 - k1.continuity) * (1 - k1.bias);
  w.in_prev = 0.5 * a2 * (1 - k2.tension) * (1 - k2.continuity) * (1 + k2.bias);
  w.in_next = 0.5 * a2 * (1 - k2.tension) * (1 + k2.continuity) * (1 - k2.bias);
  return w;
}

bool finite_tcb(const KbParams& p) {
  return std::isfinite(p.tension) && std::isfinite(p.continuity) && std::isfinite(p.bias);
}

template <typename Key>
void check_keys(const std::vector<Key>& keys) {
  if (keys.size() < 4)
    throw std::invalid_argument("a Kochanek-Bartels spline needs at least 4 keys, found " +
                                std::to_string(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (!std::isfinite(keys[i].t) || !finite_tcb(keys[i].tcb))
      throw std::invalid_argument("key " + std::to_string(i) + " is not finite");
}

// reach[i] = max(t2 of segments 0 .. i): non-decreasing, so the first segment whose end
// exceeds t, BART's linear search, is the first i with reach[i] > t, a binary search.
template <typename Segment>
std::vector<double> reaches(const std::vector<Segment>& segs) {
  std::vector<double> r;
  for (const Segment& s : segs) r.push_back(r.empty() ? s.t2 : std::max(r.back(), s.t2));
  return r;
}

// Which segment and where in it (BART's ComputeIAndU; see the header).
template <typename Segment>
std::pair<std::size_t, double> locate(const std::vector<Segment>& segs, const std::vector<double>& reach, double t) {
  if (!(segs.front().t1 < t)) return {0, 0.0};  // also catches a NaN t
  if (!(t < segs.back().t2)) return {segs.size() - 1, 1.0};
  const auto i = static_cast<std::size_t>(std::upper_bound(reach.begin(), reach.end(), t) - reach.begin());
  const Segment& s = segs[i];
  return {i, (t - s.t1) / (s.t2 - s.t1)};
}

Quatd from_axis_angle(const Vec3d& axis, double degrees) {
  const double len = std::sqrt(dot3(axis, axis));
  if (!(len > 0)) {
    if (degrees == 0) return Quatd(1, 0, 0, 0);
    throw std::invalid_argument("rotation axis is zero");
  }
  const double half = degrees * (3.14159265358979323846 / 180.0) / 2;
  const Vec3d a = axis / len * std::sin(half);
  return Quatd(std::cos(half), a.x, a.y, a.z);
}

Quatd scaled(const Quatd& q, double s) { return Quatd(q.w * s, q.x * s, q.y * s, q.z * s); }
Quatd plus(const Quatd& a, const Quatd& b) { return Quatd(a.w + b.w, a.x + b.x, a.y + b.y, a.z + b.z); }
Quatd minus(const Quatd& a, const Quatd& b) { return Quatd(a.w - b.w, a.x - b.x, a.y - b.y, a.z - b.z); }
double qdot(const Quatd& a, const Quatd& b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }
Quatd normalized(const Quatd& q) { return scaled(q, 1 / std::sqrt(qdot(q, q))); }

}  // namespace

KbVecSpline::KbVecSpline(const std::vector<KbVecKey>& k) {
  check_keys(k);
  for (const auto& key : k)
    if (!all_finite(key.value)) throw std::invalid_argument("key value is not finite");
  for (std::size_t i = 0; i + 3 < k.size(); ++i) {
    const Vec3d &p0 = k[i].value, &p1 = k[i + 1].value, &p2 = k[i + 2].value, &p3 = k[i + 3].value;
    Segment s;
    s.t1 = k[i + 1].t;
    s.t2 = k[i + 2].t;
    const Vec3d d = p2 - p1;
    const Tangents w = tcb_weights(k[i].t, s.t1, s.t2, k[i + 3].t, k[i + 1].tcb, k[i + 2].tcb);
    const Vec3d tout = (p1 - p0) * w.out_prev + d * w.out_next;
    const Vec3d tin = d * w.in_prev + (p3 - p2) * w.in_next;
    s.c0 = p1;
    s.c1 = tout;
    s.c2 = d * 3.0 - tout * 2.0 - tin;
    s.c3 = d * -2.0 + tout + tin;
    segs_.push_back(s);
  }
  reach_ = reaches(segs_);
}

Vec3d KbVecSpline::at(double t) const {
  const auto [i, u] = locate(segs_, reach_, t);
  const Segment& s = segs_[i];
  return s.c0 + (s.c1 + (s.c2 + s.c3 * u) * u) * u;
}

Quatd quat_log(const Quatd& q) {
  const double vlen = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  // angle/2 in [0, pi]; for a tiny vector part sin(angle/2) ~ angle/2, so v is the log.
  const double half = std::atan2(vlen, q.w);
  const double k = vlen > 1e-300 ? half / vlen : 1.0;
  return Quatd(0, q.x * k, q.y * k, q.z * k);
}

Quatd quat_exp(const Quatd& v) {
  const double half = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  const double k = half > 1e-300 ? std::sin(half) / half : 1.0;
  return Quatd(std::cos(half), v.x * k, v.y * k, v.z * k);
}

Quatd quat_slerp(const Quatd& p, const Quatd& q, double u) {
  const double c = std::clamp(qdot(p, q), -1.0, 1.0);
  const double angle = std::acos(c);
  const double s = std::sin(angle);
  // Nearly equal (or opposite) ends: the sine weights tend to the linear ones.
  if (std::fabs(s) < 1e-9) return normalized(plus(scaled(p, 1 - u), scaled(q, u)));
  return plus(scaled(p, std::sin((1 - u) * angle) / s), scaled(q, std::sin(u * angle) / s));
}

Quatd quat_squad(const Quatd& p, const Quatd& a, const Quatd& b, const Quatd& q, double u) {
  return quat_slerp(quat_slerp(p, q, u), quat_slerp(a, b, u), 2 * u * (1 - u));
}

KbRotSpline::KbRotSpline(const std::vector<KbRotKey>& k) {
  check_keys(k);
  std::vector<Quatd> raw;  // the keys as written
  for (const auto& key : k) {
    if (!all_finite(key.axis) || !std::isfinite(key.degrees)) throw std::invalid_argument("rotation key is not finite");
    raw.push_back(from_axis_angle(key.axis, key.degrees));
  }
  // signed[j]: key j as BART leaves it once segment j - 2 has put it in the hemisphere of
  // key j - 1 (keys 0 and 1 are never flipped).
  std::vector<Quatd> signed_q = raw;
  for (std::size_t j = 2; j < signed_q.size(); ++j)
    if (qdot(signed_q[j - 1], signed_q[j]) < 0) signed_q[j] = scaled(signed_q[j], -1);
  for (std::size_t i = 0; i + 3 < k.size(); ++i) {
    const Quatd &q0 = signed_q[i], &q1 = signed_q[i + 1], &q2 = signed_q[i + 2], &q3 = raw[i + 3];
    Segment s;
    s.t1 = k[i + 1].t;
    s.t2 = k[i + 2].t;
    s.p = q1;
    s.q = q2;
    const Tangents w = tcb_weights(k[i].t, s.t1, s.t2, k[i + 3].t, k[i + 1].tcb, k[i + 2].tcb);
    const Quatd d = quat_log(glm::conjugate(q1) * q2);  // the step q1 -> q2, in q1's frame
    const Quatd tout = plus(scaled(quat_log(glm::conjugate(q0) * q1), w.out_prev), scaled(d, w.out_next));
    const Quatd tin = plus(scaled(d, w.in_prev), scaled(quat_log(glm::conjugate(q2) * q3), w.in_next));
    s.a = q1 * quat_exp(scaled(minus(tout, d), 0.5));
    s.b = q2 * quat_exp(scaled(minus(d, tin), 0.5));
    segs_.push_back(s);
  }
  reach_ = reaches(segs_);
}

Quatd KbRotSpline::at(double t) const {
  const auto [i, u] = locate(segs_, reach_, t);
  const Segment& s = segs_[i];
  return normalized(quat_squad(s.p, s.a, s.b, s.q, u));
}

KbTimeQuirks kb_time_quirks(const std::vector<double>& t) {
  KbTimeQuirks q;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] < t[i - 1]) {
      if (!q.backwards) q.backwards = i;
      ++q.backwards_count;
    }
    if (t[i] == t[i - 1] && i >= 2 && i + 1 < t.size()) {
      if (!q.repeat) q.repeat = i;
      ++q.repeat_count;
    }
  }
  return q;
}

Affine<double> rotation_matrix(const Quatd& q) {
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  Affine<double> r;
  r.m[0][0] = 1 - 2 * (y * y + z * z);
  r.m[0][1] = 2 * (x * y - w * z);
  r.m[0][2] = 2 * (x * z + w * y);
  r.m[1][0] = 2 * (x * y + w * z);
  r.m[1][1] = 1 - 2 * (x * x + z * z);
  r.m[1][2] = 2 * (y * z - w * x);
  r.m[2][0] = 2 * (x * z - w * y);
  r.m[2][1] = 2 * (y * z + w * x);
  r.m[2][2] = 1 - 2 * (x * x + y * y);
  return r;
}

}  // namespace oprt
