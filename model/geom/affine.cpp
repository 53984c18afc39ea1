#include "geom/affine.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace oprt {

Affine<double> operator*(const Affine<double>& a, const Affine<double>& b) {
  Affine<double> r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s + (j == 3 ? a.m[i][3] : 0.0);
    }
  }
  return r;
}

Affine<double> translate(const Vec3d& t) {
  Affine<double> r;
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Affine<double> rotate(const Vec3d& axis, double radians) {
  const double len = std::sqrt(dot3(axis, axis));
  Affine<double> r;
  if (!(len > 0)) return r;
  const Vec3d a = axis / len;
  const double c = std::cos(radians), s = std::sin(radians), k = 1 - c;
  r.m[0][0] = c + a.x * a.x * k;
  r.m[0][1] = a.x * a.y * k - a.z * s;
  r.m[0][2] = a.x * a.z * k + a.y * s;
  r.m[1][0] = a.y * a.x * k + a.z * s;
  r.m[1][1] = c + a.y * a.y * k;
  r.m[1][2] = a.y * a.z * k - a.x * s;
  r.m[2][0] = a.z * a.x * k - a.y * s;
  r.m[2][1] = a.z * a.y * k + a.x * s;
  r.m[2][2] = c + a.z * a.z * k;
  return r;
}

Affine<double> scale(const Vec3d& s) {
  Affine<double> r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

namespace {
double det3(const Affine<double>& a) {
  const auto& m = a.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
double column_length(const Affine<double>& a, int j) {
  return std::sqrt(a.m[0][j] * a.m[0][j] + a.m[1][j] * a.m[1][j] + a.m[2][j] * a.m[2][j]);
}
// Below this, the columns are so nearly dependent that float rays transformed by the
// inverse lose all their bits; a well-shaped map has 1.
constexpr double kMinRelativeDet = 1e-9;
}  // namespace

std::string why_not_invertible(const Affine<double>& a) {
  if (!a.finite()) return "matrix has a NaN or infinite entry";
  const double det = det3(a);
  const double scale_free = column_length(a, 0) * column_length(a, 1) * column_length(a, 2);
  if (!std::isfinite(det) || !std::isfinite(scale_free))
    return "matrix entries are too large (its determinant overflows double precision)";
  if (det == 0 || !(scale_free > 0)) return "matrix is singular (determinant 0)";
  if (!(std::fabs(det) >= kMinRelativeDet * scale_free)) {
    std::ostringstream s;
    s << "matrix is nearly singular (|det| / product of column lengths = "
      << std::fabs(det) / scale_free << ", below " << kMinRelativeDet << ")";
    return s.str();
  }
  return {};
}

std::optional<Affine<double>> inverse(const Affine<double>& a) {
  if (!why_not_invertible(a).empty()) return std::nullopt;
  const auto& m = a.m;
  const double inv_det = 1.0 / det3(a);
  Affine<double> r;
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv_det;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv_det;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv_det;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det;
  for (int i = 0; i < 3; ++i)
    r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
  return r;
}

double max_stretch(const Affine<double>& a) {
  // G = L^T L, symmetric positive semi-definite; its largest eigenvalue by the
  // trigonometric closed form (Smith 1961).
  double g[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += a.m[k][i] * a.m[k][j];
      g[i][j] = s;
    }
  const double p1 = g[0][1] * g[0][1] + g[0][2] * g[0][2] + g[1][2] * g[1][2];
  double lambda;
  if (p1 == 0) {
    lambda = std::max({g[0][0], g[1][1], g[2][2]});
  } else {
    const double q = (g[0][0] + g[1][1] + g[2][2]) / 3;
    const double p2 = (g[0][0] - q) * (g[0][0] - q) + (g[1][1] - q) * (g[1][1] - q) +
                      (g[2][2] - q) * (g[2][2] - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    double b[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) b[i][j] = (g[i][j] - (i == j ? q : 0)) / p;
    const double r = 0.5 * (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                            b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                            b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]));
    const double phi = std::acos(std::clamp(r, -1.0, 1.0)) / 3;
    lambda = q + 2 * p * std::cos(phi);
  }
  // The closed form loses a few bits near repeated eigenvalues; it is a bound on a radius,
  // so round up generously (the Frobenius norm is a cap that is always safe).
  double frob = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) frob += a.m[i][j] * a.m[i][j];
  return std::min(std::sqrt(std::max(lambda, 0.0)) * (1 + 1e-9), std::sqrt(frob) * (1 + 1e-12));
}

std::optional<Placement> make_placement(const Affine<double>& to_world) {
  auto inv = inverse(to_world);
  if (!inv) return std::nullopt;
  return Placement{to_world, *inv};
}

}  // namespace oprt
