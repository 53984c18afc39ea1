// Small vector types shared by every part of oprt: GLM's vectors, named for the
// precision they are instantiated with. The kernels are templates on T = float | double.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <limits>

namespace oprt {

template <typename T>
using Vec3 = glm::vec<3, T, glm::defaultp>;
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

// Sums written out left to right: the order of the additions is part of a kernel's result
// (the reference and the model must round identically), so no library call decides it.
template <typename T>
inline T dot3(const Vec3<T>& a, const Vec3<T>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

template <typename T>
inline Vec3<T> cross3(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <typename T>
inline bool all_finite(const Vec3<T>& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

template <typename T>
inline T max_abs_component(const Vec3<T>& v) {
  return std::fmax(std::fabs(v.x), std::fmax(std::fabs(v.y), std::fabs(v.z)));
}

template <typename T>
constexpr T kInf = std::numeric_limits<T>::infinity();

// Unit roundoff and pbrt's gamma(n) = n u / (1 - n u): the bound on the relative error of
// n successive roundings.
template <typename T>
constexpr T unit_roundoff() { return std::numeric_limits<T>::epsilon() * T(0.5); }
template <typename T>
constexpr T gamma(int n) { return (n * unit_roundoff<T>()) / (1 - n * unit_roundoff<T>()); }

}  // namespace oprt
