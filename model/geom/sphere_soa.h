// A unit's world spheres as streams (centre x, y, z, radius), so that the sphere test runs
// over kLanes<T> spheres at a time (geom/simd_kernels.h), and the one place that chooses
// between that and the scalar hit_sphere.
#pragma once

#include "geom/simd_kernels.h"
#include "geom/sphere.h"

#include <vector>

namespace oprt {

template <typename T>
struct SphereSoA {
  std::vector<T> c[4];  // cx, cy, cz, r

  std::size_t size() const { return c[0].size(); }
  void clear() {
    for (auto& s : c) s.clear();
  }
  void push_back(const Sphere<T>& s) {
    c[0].push_back(s.c.x);
    c[1].push_back(s.c.y);
    c[2].push_back(s.c.z);
    c[3].push_back(s.r);
  }
};

// Bit j set: hit_sphere(ray, spheres[i + j]), for j < n <= kLanes<T>. `soa` holds the same
// spheres as streams (if it does not hold as many, the scalar test runs).
template <typename T>
inline unsigned sphere_hits(const std::vector<Sphere<T>>& spheres, const SphereSoA<T>& soa, const Ray<T>& ray,
                            std::size_t i, unsigned n) {
#if OPRT_HAVE_AVX2
  const SimdMode mode = simd_mode();
  const bool streams = soa.size() == spheres.size();
  const T* s[4] = {soa.c[0].data(), soa.c[1].data(), soa.c[2].data(), soa.c[3].data()};
  if (mode == SimdMode::on && streams) return simd::sphere_chunk(s, i, n, ray);
#else
  (void)soa;
#endif
  unsigned m = 0;
  for (unsigned j = 0; j < n; ++j) m |= static_cast<unsigned>(hit_sphere(ray, spheres[i + j])) << j;
#if OPRT_HAVE_AVX2
  if (mode == SimdMode::check && streams) {
    if (simd::sphere_chunk(s, i, n, ray) != m) detail::simd_mismatch("sphere test", i);
    detail::simd_checked();
  }
#endif
  return m;
}

}  // namespace oprt
