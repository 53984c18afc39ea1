// Affine maps x' = L x + t (3x4, row-major), and the rigid-object transform that keeps a
// map together with its inverse, computed once (pbrt's Transform does the same).
#pragma once

#include "geom/ray.h"

#include <array>
#include <optional>
#include <string>

namespace oprt {

template <typename T>
struct Affine {
  // m[r][0..2] is row r of L, m[r][3] is t[r].
  T m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Affine identity() { return Affine{}; }
  static Affine from_rows(const std::array<T, 12>& a) {
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) r.m[i][j] = a[4 * i + j];
    return r;
  }

  // Operation order is fixed (((m0 x + m1 y) + m2 z) + t): the IU's 19-cycle transform
  // schedule computes exactly these roundings.
  Vec3<T> point(const Vec3<T>& p) const {
    return {((m[0][0] * p.x + m[0][1] * p.y) + m[0][2] * p.z) + m[0][3],
            ((m[1][0] * p.x + m[1][1] * p.y) + m[1][2] * p.z) + m[1][3],
            ((m[2][0] * p.x + m[2][1] * p.y) + m[2][2] * p.z) + m[2][3]};
  }
  Vec3<T> vector(const Vec3<T>& v) const {
    return {(m[0][0] * v.x + m[0][1] * v.y) + m[0][2] * v.z,
            (m[1][0] * v.x + m[1][1] * v.y) + m[1][2] * v.z,
            (m[2][0] * v.x + m[2][1] * v.y) + m[2][2] * v.z};
  }
  Vec3<T> translation() const { return {m[0][3], m[1][3], m[2][3]}; }

  // A ray carried into another frame keeps its parameter: the direction is transformed as
  // a vector and deliberately NOT renormalised, so o' + t d' is the image of o + t d for
  // the same t. Hits found in different local frames then compare by t directly, and the
  // nearest hit over all objects needs no conversion back to world space.
  Ray<T> ray(const Ray<T>& r) const { return {point(r.o), vector(r.d), r.tmax}; }

  template <typename U>
  Affine<U> cast() const {
    Affine<U> r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) r.m[i][j] = static_cast<U>(m[i][j]);
    return r;
  }

  bool finite() const {
    for (auto& row : m)
      for (T x : row)
        if (!std::isfinite(x)) return false;
    return true;
  }
};

// a after b: (a * b)(x) = a(b(x)).
Affine<double> operator*(const Affine<double>& a, const Affine<double>& b);

// Translate, rotate (axis, angle) and scale matrices; compose as T * R * S.
Affine<double> translate(const Vec3d& t);
Affine<double> rotate(const Vec3d& axis, double radians);
Affine<double> scale(const Vec3d& s);

// The inverse, or nothing when the map is not finite or is singular: |det L| is compared
// with the product of the column lengths, a scale-free measure, so tiny but well-shaped
// objects (scale 1e-4) are accepted while a collapsed or flattening map is rejected.
std::optional<Affine<double>> inverse(const Affine<double>& a);
// Why inverse() refused (for error messages), empty if it would succeed.
std::string why_not_invertible(const Affine<double>& a);

// Upper bound on the largest singular value of L, the factor by which the map can stretch
// a length: radius of a transformed sphere. sqrt of the largest eigenvalue of L^T L, from
// the closed form for a symmetric 3x3, enlarged by a small relative margin that covers its
// own rounding.
double max_stretch(const Affine<double>& a);

// A rigid object's placement: local -> world and its inverse, both kept.
struct Placement {
  Affine<double> to_world;
  Affine<double> to_local;
};
std::optional<Placement> make_placement(const Affine<double>& to_world);

}  // namespace oprt
