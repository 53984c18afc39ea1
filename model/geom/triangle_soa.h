// Triangles as object memory streams them: structure of arrays, one array per component,
// so a block of consecutive triangles loads as vectors (the SIMD kernels read 8 or 16 at a
// time). A sphere's triangles are one contiguous range.
#pragma once

#include "geom/triangle.h"

#include <cstdint>
#include <vector>

namespace oprt {

template <typename T>
struct MollerSoA {
  // v0, e1, e2, n: 12 streams.
  std::vector<T> c[12];

  std::size_t size() const { return c[0].size(); }
  void reserve(std::size_t n) {
    for (auto& s : c) s.reserve(n);
  }
  void push_back(const MollerTriangle<T>& t) {
    const Vec3<T>* v[4] = {&t.v0, &t.e1, &t.e2, &t.n};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) c[3 * k + j].push_back((*v[k])[j]);
  }
  MollerTriangle<T> operator[](std::size_t i) const {
    return {{c[0][i], c[1][i], c[2][i]}, {c[3][i], c[4][i], c[5][i]},
            {c[6][i], c[7][i], c[8][i]}, {c[9][i], c[10][i], c[11][i]}};
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

// Nearest hit over triangles [first, end); adds each test's exit stage to stages[] and the
// accepted tests to *hits; if `log` is given, writes each test's exit stage to log[k - first]
// (the memory model needs the order). Among equal t the first (lowest index) wins.
template <typename T>
inline BlockHit<T> nearest_in_block(const MollerSoA<T>& soa, std::uint32_t first, std::uint32_t end,
                                    const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits,
                                    std::uint8_t* log = nullptr) {
  BlockHit<T> best;
  for (std::uint32_t k = first; k < end; ++k) {
    const TriangleHit<T> h = intersect_moller(ray, soa[k]);
    ++stages[static_cast<int>(h.stage)];
    if (log) log[k - first] = static_cast<std::uint8_t>(h.stage);
    if (h.hit) {
      ++*hits;
      if (h.t < best.t) best = {h.t, k, h.u, h.v};
    }
  }
  return best;
}

// First hit over [first, end) in order; stops there. Returns whether there was one.
template <typename T>
inline bool any_in_block(const MollerSoA<T>& soa, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                         std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log = nullptr) {
  for (std::uint32_t k = first; k < end; ++k) {
    const TriangleHit<T> h = intersect_moller(ray, soa[k]);
    ++stages[static_cast<int>(h.stage)];
    if (log) log[k - first] = static_cast<std::uint8_t>(h.stage);
    if (h.hit) {
      ++*hits;
      return true;
    }
  }
  return false;
}

}  // namespace oprt
