// Triangles as object memory streams them: structure of arrays, one array per component,
// so a block of consecutive triangles loads as vectors (the SIMD kernels read 8 or 16 at a
// time). A sphere's triangles are one contiguous range. Each kernel has its own format; the
// block functions at the end are the one place that dispatches on the kernel.
#pragma once

#include "geom/triangle.h"
#include "geom/watertight.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace oprt {

// A triangle format's Vec3 fields, in stream order (what object memory stores per triangle).
template <typename T>
std::array<Vec3<T>*, 4> fields(MollerTriangle<T>& t) {
  return {&t.v0, &t.e1, &t.e2, &t.n};
}
template <typename T>
std::array<Vec3<T>*, 3> fields(WatertightTriangle<T>& t) {
  return {&t.v0, &t.v1, &t.v2};
}

// Structure of arrays of a format of N Vec3 fields: 3 N streams of T.
template <typename T, typename Tri, int N>
struct Vec3SoA {
  std::vector<T> c[3 * N];

  std::size_t size() const { return c[0].size(); }
  void reserve(std::size_t n) {
    for (auto& s : c) s.reserve(n);
  }
  void push_back(Tri t) {
    const auto f = fields(t);
    for (int k = 0; k < N; ++k)
      for (int j = 0; j < 3; ++j) c[3 * k + j].push_back((*f[k])[j]);
  }
  Tri operator[](std::size_t i) const {
    Tri t;
    const auto f = fields(t);
    for (int k = 0; k < N; ++k) *f[k] = {c[3 * k][i], c[3 * k + 1][i], c[3 * k + 2][i]};
    return t;
  }
  void write(std::size_t i, Tri t) {
    const auto f = fields(t);
    for (int k = 0; k < N; ++k)
      for (int j = 0; j < 3; ++j) c[3 * k + j][i] = (*f[k])[j];
  }
};

template <typename T>
struct MollerSoA : Vec3SoA<T, MollerTriangle<T>, 4> {  // v0, e1, e2, n
  TriangleHit<T> intersect(const Ray<T>& ray, std::size_t i) const { return intersect_moller(ray, (*this)[i]); }
};

template <typename T>
struct WatertightSoA : Vec3SoA<T, WatertightTriangle<T>, 3> {  // v0, v1, v2
  TriangleHit<T, WtStage> intersect(const WatertightRay<T>& ray, std::size_t i) const {
    return intersect_watertight(ray, (*this)[i]);
  }
};

// Bytes one triangle occupies in object memory (what the memory and bus models charge).
template <typename T>
constexpr unsigned triangle_bytes(Kernel k) {
  return (k == Kernel::watertight ? 9 : 12) * static_cast<unsigned>(sizeof(T));
}

// An object memory's triangles in the format of the kernel it serves (the other format
// stays empty).
template <typename T>
struct TriangleStore {
  Kernel kernel = Kernel::moller;
  MollerSoA<T> moller;
  WatertightSoA<T> watertight;

  explicit TriangleStore(Kernel k = Kernel::moller) : kernel(k) {}
  std::size_t size() const { return kernel == Kernel::watertight ? watertight.size() : moller.size(); }
  unsigned bytes_per_triangle() const { return triangle_bytes<T>(kernel); }
  void reserve(std::size_t n) { kernel == Kernel::watertight ? watertight.reserve(n) : moller.reserve(n); }
  // Prepare a triangle from the model's (double) vertices and append it, or rewrite entry i.
  void push_back(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    if (kernel == Kernel::watertight) watertight.push_back(prepare_watertight<T>(a, b, c));
    else moller.push_back(prepare_moller<T>(a, b, c));
  }
  void write(std::size_t i, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    if (kernel == Kernel::watertight) watertight.write(i, prepare_watertight<T>(a, b, c));
    else moller.write(i, prepare_moller<T>(a, b, c));
  }
  // Is everything stored for triangle i finite?
  bool finite(std::size_t i) const {
    auto all = [i](const auto& streams) {
      for (const auto& c : streams)
        if (!std::isfinite(c[i])) return false;
      return true;
    };
    return kernel == Kernel::watertight ? all(watertight.c) : all(moller.c);
  }
};

// Result of testing one ray against a block of triangles.
template <typename T>
struct BlockHit {
  T t = kInf<T>;
  std::uint32_t index = 0xFFFFFFFFu;  // into the SoA; the lowest index among equal t
  T u = 0, v = 0;
  bool valid() const { return index != 0xFFFFFFFFu; }
};

namespace detail {
template <typename T, typename Soa, typename R>
inline BlockHit<T> nearest_loop(const Soa& soa, std::uint32_t first, std::uint32_t end, const R& ray,
                                std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
  BlockHit<T> best;
  for (std::uint32_t k = first; k < end; ++k) {
    const auto h = soa.intersect(ray, k);
    ++stages[static_cast<int>(h.stage)];
    if (log) log[k - first] = static_cast<std::uint8_t>(h.stage);
    if (h.hit) {
      ++*hits;
      if (h.t < best.t) best = {h.t, k, h.u, h.v};
    }
  }
  return best;
}

template <typename Soa, typename R>
inline bool any_loop(const Soa& soa, std::uint32_t first, std::uint32_t end, const R& ray, std::uint64_t* stages,
                     std::uint64_t* hits, std::uint8_t* log) {
  for (std::uint32_t k = first; k < end; ++k) {
    const auto h = soa.intersect(ray, k);
    ++stages[static_cast<int>(h.stage)];
    if (log) log[k - first] = static_cast<std::uint8_t>(h.stage);
    if (h.hit) {
      ++*hits;
      return true;
    }
  }
  return false;
}
}  // namespace detail

// Nearest hit over triangles [first, end); adds each test's exit stage to stages[] and the
// accepted tests to *hits; if `log` is given, writes each test's exit stage to log[k - first]
// (the memory model needs the order). Among equal t the first (lowest index) wins. The
// watertight kernel's per-ray set-up (dominant axis) is redone per block: the unit does it
// once per transform, and its cost is in the transform's (hw/cycle_schedule.cpp).
template <typename T>
inline BlockHit<T> nearest_in_block(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end,
                                    const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits,
                                    std::uint8_t* log = nullptr) {
  if (m.kernel == Kernel::watertight)
    return detail::nearest_loop<T>(m.watertight, first, end, watertight_ray(ray), stages, hits, log);
  return detail::nearest_loop<T>(m.moller, first, end, ray, stages, hits, log);
}

// First hit over [first, end) in order; stops there. Returns whether there was one.
template <typename T>
inline bool any_in_block(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                         std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log = nullptr) {
  if (m.kernel == Kernel::watertight)
    return detail::any_loop(m.watertight, first, end, watertight_ray(ray), stages, hits, log);
  return detail::any_loop(m.moller, first, end, ray, stages, hits, log);
}

}  // namespace oprt
