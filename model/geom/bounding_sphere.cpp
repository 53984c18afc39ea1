#include "geom/bounding_sphere.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace oprt {

double enclosing_radius(const std::vector<Vec3d>& points, const Vec3d& c) {
  double r2 = 0;
  for (const Vec3d& p : points) r2 = std::max(r2, dot3(p - c, p - c));
  return std::sqrt(r2);
}

namespace {

struct Ball {
  Vec3d c{0};
  double r2 = -1;  // empty
  bool contains(const Vec3d& p) const {
    const Vec3d d = p - c;
    // Relative slack: points found on the boundary by the support computations must
    // count as inside, or the loops would chase rounding noise.
    return dot3(d, d) <= r2 * (1 + 1e-12) + 1e-300;
  }
};

Ball ball_of(const Vec3d& a) { return {a, 0}; }

Ball ball_of(const Vec3d& a, const Vec3d& b) {
  const Vec3d c = (a + b) * 0.5;
  return {c, dot3(a - c, a - c)};
}

// Smallest sphere with a, b, c on its boundary: the circumcircle of the triangle.
Ball ball_of(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d ab = b - a, ac = c - a;
  const Vec3d n = cross3(ab, ac);
  const double nn = dot3(n, n);
  if (!(nn > 1e-30 * dot3(ab, ab) * dot3(ac, ac))) {
    // Collinear: the two farthest points span the ball.
    Ball best = ball_of(a, b);
    for (const Ball& q : {ball_of(a, c), ball_of(b, c)})
      if (q.r2 > best.r2) best = q;
    return best;
  }
  const Vec3d o = (cross3(n, ab) * dot3(ac, ac) + cross3(ac, n) * dot3(ab, ab)) / (2 * nn);
  return {a + o, dot3(o, o)};
}

// Sphere through four points: the circumsphere of the tetrahedron.
Ball ball_of(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Vec3d u = b - a, v = c - a, w = d - a;
  const double det = 2 * dot3(u, cross3(v, w));
  const double scale = std::sqrt(dot3(u, u) * dot3(v, v) * dot3(w, w));
  if (!(std::fabs(det) > 1e-12 * scale)) {
    // Coplanar: fall back to the largest of the triangle circles that holds all four.
    Ball best;
    for (const Ball& q : {ball_of(a, b, c), ball_of(a, b, d), ball_of(a, c, d), ball_of(b, c, d)})
      if (q.contains(a) && q.contains(b) && q.contains(c) && q.contains(d) &&
          (best.r2 < 0 || q.r2 < best.r2))
        best = q;
    if (best.r2 >= 0) return best;
    return ball_of(a, b, c);
  }
  const Vec3d o =
      (cross3(v, w) * dot3(u, u) + cross3(w, u) * dot3(v, v) + cross3(u, v) * dot3(w, w)) / det;
  return {a + o, dot3(o, o)};
}

}  // namespace

Sphere<double> minimal_sphere(const std::vector<Vec3d>& input) {
  if (input.empty()) return {Vec3d(0), 0};
  std::vector<Vec3d> p = input;
  std::mt19937_64 rng(0x5eedba11);
  std::shuffle(p.begin(), p.end(), rng);
  const size_t n = p.size();
  Ball b = ball_of(p[0]);
  for (size_t i = 1; i < n; ++i) {
    if (b.contains(p[i])) continue;
    b = ball_of(p[i]);
    for (size_t j = 0; j < i; ++j) {
      if (b.contains(p[j])) continue;
      b = ball_of(p[i], p[j]);
      for (size_t k = 0; k < j; ++k) {
        if (b.contains(p[k])) continue;
        b = ball_of(p[i], p[j], p[k]);
        for (size_t l = 0; l < k; ++l) {
          if (b.contains(p[l])) continue;
          b = ball_of(p[i], p[j], p[k], p[l]);
        }
      }
    }
  }
  return {b.c, enclosing_radius(input, b.c)};
}

Sphere<double> ritter_sphere(const std::vector<Vec3d>& p) {
  if (p.empty()) return {Vec3d(0), 0};
  auto farthest = [&](const Vec3d& from) {
    size_t best = 0;
    double d2 = -1;
    for (size_t i = 0; i < p.size(); ++i) {
      const double q = dot3(p[i] - from, p[i] - from);
      if (q > d2) d2 = q, best = i;
    }
    return p[best];
  };
  const Vec3d x = farthest(p[0]), y = farthest(x);
  Vec3d c = (x + y) * 0.5;
  double r = std::sqrt(dot3(y - c, y - c));
  for (const Vec3d& q : p) {
    const double d = std::sqrt(dot3(q - c, q - c));
    if (d > r) {
      const double nr = (r + d) * 0.5;
      c += (q - c) * ((nr - r) / d);
      r = nr;
    }
  }
  return {c, enclosing_radius(p, c)};
}

}  // namespace oprt
