// Triangles as object memory streams them: structure of arrays, one stream per component,
// in blocks of 8 floats or 4 doubles, so that the SIMD kernels (geom/simd_kernels.h) load a
// block's triangles as vectors. A sphere's triangles are one contiguous range. Each kernel
// has its own format; the block functions at the end are the one place that dispatches on
// the kernel, and on the scalar or SIMD kernels (simd_mode(), geom/simd.h).
#pragma once

#include "geom/simd_kernels.h"
#include "geom/triangle.h"
#include "geom/watertight.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
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

// Structure of arrays of a format of N Vec3 fields: 3 N streams of T, stored in blocks of
// W = kLanes<T> triangles (Embree's layout): block b holds triangles b W .. b W + W - 1,
// stream after stream, W values each. The W triangles of a block load as 3 N vectors from
// one address; triangle i's stream j is at block(i / W)[j W + i % W]. The last block is
// padded with zeros (zero-area triangles, outside every range the block functions test).
template <typename T, typename Tri, int N>
struct Vec3SoA {
  static constexpr int kStreams = 3 * N;
  static constexpr std::size_t W = kLanes<T>;

  std::size_t size() const { return n_; }
  void reserve(std::size_t n) { data_.reserve((n + W - 1) / W * W * kStreams); }
  // Stream j (field j / 3, component j % 3) of triangle i.
  T get(std::size_t i, int j) const { return data_[(i / W) * W * kStreams + j * W + i % W]; }
  const T* block(std::size_t b) const { return data_.data() + b * W * kStreams; }
  void push_back(Tri t) {
    if (n_ % W == 0) data_.resize(data_.size() + W * kStreams, T(0));
    write(n_++, t);
  }
  Tri operator[](std::size_t i) const {
    Tri t;
    const auto f = fields(t);
    for (int k = 0; k < N; ++k) *f[k] = {get(i, 3 * k), get(i, 3 * k + 1), get(i, 3 * k + 2)};
    return t;
  }
  void write(std::size_t i, Tri t) {
    const auto f = fields(t);
    for (int k = 0; k < N; ++k)
      for (int j = 0; j < 3; ++j) data_[(i / W) * W * kStreams + (3 * k + j) * W + i % W] = (*f[k])[j];
  }
  bool finite(std::size_t i) const {
    for (int j = 0; j < kStreams; ++j)
      if (!std::isfinite(get(i, j))) return false;
    return true;
  }

 private:
  std::vector<T> data_;
  std::size_t n_ = 0;
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
  bool finite(std::size_t i) const { return kernel == Kernel::watertight ? watertight.finite(i) : moller.finite(i); }
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
// The scalar loops are functions of their own (noinline): called once per block, and inside
// them the compiler inlines the scalar kernel, which it stops doing when the loop is
// inlined into a large caller (18 % slower).
template <typename T, typename Soa, typename R>
__attribute__((noinline)) BlockHit<T> nearest_loop(const Soa& soa, std::uint32_t first, std::uint32_t end, const R& ray,
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
__attribute__((noinline)) bool any_loop(const Soa& soa, std::uint32_t first, std::uint32_t end, const R& ray,
                                        std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
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

template <typename T>
inline BlockHit<T> nearest_scalar(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                                  std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
  if (m.kernel == Kernel::watertight)
    return nearest_loop<T>(m.watertight, first, end, watertight_ray(ray), stages, hits, log);
  return nearest_loop<T>(m.moller, first, end, ray, stages, hits, log);
}

template <typename T>
inline bool any_scalar(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                       std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
  if (m.kernel == Kernel::watertight) return any_loop(m.watertight, first, end, watertight_ray(ray), stages, hits, log);
  return any_loop(m.moller, first, end, ray, stages, hits, log);
}

#if OPRT_HAVE_AVX2
// The block loops over the SIMD chunk kernels (geom/simd_kernels.h): chunk(b, lanes) tests
// the triangles of the storage block that starts at triangle b (a multiple of W) on the
// lanes of `lanes`, those of [first, end). Exit stages are counted from the stage masks
// (popcounts, added to `stages` once per block call) and logged as the sum of the masks
// spread to bytes; the lanes are merged in memory order with the scalar loop's rules.
struct StageTally {
  std::uint64_t tested = 0, pass[3] = {0, 0, 0}, hits = 0;
  void add(unsigned lanes, const unsigned* p) {
    tested += static_cast<unsigned>(__builtin_popcount(lanes));
    for (int s = 0; s < 3; ++s) pass[s] += static_cast<unsigned>(__builtin_popcount(p[s] & lanes));
  }
  void flush(std::uint64_t* stages, std::uint64_t* h) const {
    stages[0] += tested - pass[0];
    stages[1] += pass[0] - pass[1];
    stages[2] += pass[1] - pass[2];
    stages[3] += pass[2];
    *h += hits;
  }
};

// Lanes lo .. hi-1 of a chunk: their exit stages to dst[0 .. hi-lo-1].
inline void log_chunk(std::uint8_t* dst, unsigned lo, unsigned hi, const unsigned* p) {
  const std::uint64_t bytes = (spread_bits(p[0]) + spread_bits(p[1]) + spread_bits(p[2])) >> (8 * lo);
  std::memcpy(dst, &bytes, hi - lo);
}

// The lanes of the storage block starting at triangle b that lie in [first, end).
template <typename T>
struct ChunkLanes {
  unsigned lo, hi, mask;
  ChunkLanes(std::uint32_t b, std::uint32_t first, std::uint32_t end)
      : lo(first > b ? first - b : 0), hi(end - b < kLanes<T> ? end - b : kLanes<T>),
        mask(lanes_below(hi) & ~lanes_below(lo)) {}
};

// (The chunk object is taken by value: a local copy that log writes cannot alias keeps the
// ray in registers.)
template <typename T, typename Chunk>
inline BlockHit<T> nearest_chunks(std::uint32_t first, std::uint32_t end, const Chunk chunk, std::uint64_t* stages,
                                  std::uint64_t* hits, std::uint8_t* log) {
  constexpr unsigned W = kLanes<T>;
  BlockHit<T> best;
  StageTally tally;
  for (std::uint32_t b = first / W * W; b < end; b += W) {
    const ChunkLanes<T> in(b, first, end);
    const simd::ChunkResult<T> r = chunk(b, in.mask);
    tally.add(in.mask, r.pass);
    if (log) log_chunk(log + (b + in.lo - first), in.lo, in.hi, r.pass);
    if (r.hit) {
      tally.hits += static_cast<unsigned>(__builtin_popcount(r.hit));
      const simd::Lanes<T> t(r.t), un(r.un), vn(r.vn), den(r.den);
      for (unsigned m = r.hit; m; m &= m - 1) {
        const unsigned i = static_cast<unsigned>(__builtin_ctz(m));
        if (t[i] < best.t) best = {t[i], b + i, un[i] / den[i], vn[i] / den[i]};
      }
    }
  }
  tally.flush(stages, hits);
  return best;
}

template <typename T, typename Chunk>
inline bool any_chunks(std::uint32_t first, std::uint32_t end, const Chunk chunk, std::uint64_t* stages,
                       std::uint64_t* hits, std::uint8_t* log) {
  constexpr unsigned W = kLanes<T>;
  StageTally tally;
  for (std::uint32_t b = first / W * W; b < end; b += W) {
    ChunkLanes<T> in(b, first, end);
    const simd::ChunkResult<T> r = chunk(b, in.mask);
    if (r.hit) {  // the tests made: up to the first hit
      in.hi = static_cast<unsigned>(__builtin_ctz(r.hit)) + 1;
      in.mask &= lanes_below(in.hi);
    }
    tally.add(in.mask, r.pass);
    if (log) log_chunk(log + (b + in.lo - first), in.lo, in.hi, r.pass);
    if (r.hit) {
      tally.hits = 1;
      tally.flush(stages, hits);
      return true;
    }
  }
  tally.flush(stages, hits);
  return false;
}

// The kernel's storage and the ray in the chunk kernel's form, once per block call.
template <typename T>
struct MollerChunks {
  const MollerSoA<T>* m;
  simd::MollerRayPack<T> r;
  MollerChunks(const MollerSoA<T>& soa, const Ray<T>& ray) : m(&soa), r(ray) {}
  OPRT_SIMD_INLINE simd::ChunkResult<T> operator()(std::uint32_t b, unsigned lanes) const {
    return simd::moller_chunk(m->block(b / kLanes<T>), lanes, r);
  }
};

// The watertight kernel reads the vertices' components in the ray's permuted order, fixed
// at compile time per dominant axis KZ (three instances): every load has a constant offset.
template <typename T, int KZ>
struct WatertightChunks {
  const WatertightSoA<T>* m;
  simd::WatertightRayPack<T> r;
  WatertightChunks(const WatertightSoA<T>& soa, const WatertightRay<T>& w) : m(&soa), r(w) {}
  OPRT_SIMD_INLINE simd::ChunkResult<T> operator()(std::uint32_t b, unsigned lanes) const {
    return simd::watertight_chunk<T, KZ>(m->block(b / kLanes<T>), lanes, r);
  }
};

// Called once per block, like the scalar loops, and likewise not inlined into the callers
// (whose register pressure would otherwise spill the ray).
template <typename T>
__attribute__((noinline)) BlockHit<T> nearest_simd(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end,
                                                   const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits,
                                                   std::uint8_t* log) {
  if (m.kernel == Kernel::watertight) {
    const WatertightRay<T> w = watertight_ray(ray);
    if (w.kz == 0) return nearest_chunks<T>(first, end, WatertightChunks<T, 0>(m.watertight, w), stages, hits, log);
    if (w.kz == 1) return nearest_chunks<T>(first, end, WatertightChunks<T, 1>(m.watertight, w), stages, hits, log);
    return nearest_chunks<T>(first, end, WatertightChunks<T, 2>(m.watertight, w), stages, hits, log);
  }
  return nearest_chunks<T>(first, end, MollerChunks<T>(m.moller, ray), stages, hits, log);
}

template <typename T>
__attribute__((noinline)) bool any_simd(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end,
                                        const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits,
                                        std::uint8_t* log) {
  if (m.kernel == Kernel::watertight) {
    const WatertightRay<T> w = watertight_ray(ray);
    if (w.kz == 0) return any_chunks<T>(first, end, WatertightChunks<T, 0>(m.watertight, w), stages, hits, log);
    if (w.kz == 1) return any_chunks<T>(first, end, WatertightChunks<T, 1>(m.watertight, w), stages, hits, log);
    return any_chunks<T>(first, end, WatertightChunks<T, 2>(m.watertight, w), stages, hits, log);
  }
  return any_chunks<T>(first, end, MollerChunks<T>(m.moller, ray), stages, hits, log);
}
#endif  // OPRT_HAVE_AVX2

// OPRT_SIMD=check: run both, compare every output, bit for bit.
template <typename T>
inline bool same_bits(T a, T b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

struct BlockOutputs {
  std::uint64_t stages[kTriStages] = {}, hits = 0;
  std::vector<std::uint8_t> log;
  BlockOutputs(std::uint32_t n, bool logged) : log(logged ? n : 0) {}
  std::uint8_t* log_data() { return log.empty() ? nullptr : log.data(); }
  void compare(const BlockOutputs& o, std::uint32_t first) const {
    simd_checked();
    for (int s = 0; s < kTriStages; ++s)
      if (stages[s] != o.stages[s]) simd_mismatch("exit-stage count", first);
    if (hits != o.hits) simd_mismatch("hit count", first);
    if (log != o.log) simd_mismatch("exit-stage log", first);
  }
  void add_to(std::uint64_t* st, std::uint64_t* h, std::uint8_t* l) const {
    for (int s = 0; s < kTriStages; ++s) st[s] += stages[s];
    *h += hits;
    if (l) std::copy(log.begin(), log.end(), l);
  }
};

template <typename T>
inline BlockHit<T> nearest_checked(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end,
                                   const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
  BlockOutputs a(end - first, log != nullptr), b(end - first, log != nullptr);
  const BlockHit<T> ha = nearest_scalar(m, first, end, ray, a.stages, &a.hits, a.log_data());
  BlockHit<T> hb = ha;
#if OPRT_HAVE_AVX2
  hb = nearest_simd(m, first, end, ray, b.stages, &b.hits, b.log_data());
#else
  b = a;
#endif
  if (ha.index != hb.index || !same_bits(ha.t, hb.t) || !same_bits(ha.u, hb.u) || !same_bits(ha.v, hb.v))
    simd_mismatch("nearest hit", first);
  a.compare(b, first);
  a.add_to(stages, hits, log);
  return ha;
}

template <typename T>
inline bool any_checked(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                        std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log) {
  BlockOutputs a(end - first, log != nullptr), b(end - first, log != nullptr);
  const bool ha = any_scalar(m, first, end, ray, a.stages, &a.hits, a.log_data());
  bool hb = ha;
#if OPRT_HAVE_AVX2
  hb = any_simd(m, first, end, ray, b.stages, &b.hits, b.log_data());
#else
  b = a;
#endif
  if (ha != hb) simd_mismatch("any hit", first);
  a.compare(b, first);
  a.add_to(stages, hits, log);
  return ha;
}
}  // namespace detail

// Nearest hit over triangles [first, end); adds each test's exit stage to stages[] and the
// accepted tests to *hits; if `log` is given, writes each test's exit stage to log[k - first]
// (the memory model needs the order). Among equal t the first (lowest index) wins. The
// watertight kernel's per-ray set-up (dominant axis) is redone per block: the unit does it
// once per transform, and its cost is in the transform's (arch/cycle_schedule.cpp).
// The SIMD kernels (geom/simd_kernels.h) give the same results as the scalar ones; which
// run is simd_mode()'s choice (geom/simd.h).
template <typename T>
inline BlockHit<T> nearest_in_block(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end,
                                    const Ray<T>& ray, std::uint64_t* stages, std::uint64_t* hits,
                                    std::uint8_t* log = nullptr) {
  switch (simd_mode()) {
#if OPRT_HAVE_AVX2
    case SimdMode::on: return detail::nearest_simd(m, first, end, ray, stages, hits, log);
#endif
    case SimdMode::check: return detail::nearest_checked(m, first, end, ray, stages, hits, log);
    default: return detail::nearest_scalar(m, first, end, ray, stages, hits, log);
  }
}

// First hit over [first, end) in order; stops there. Returns whether there was one. The
// stage counts and the log hold the tests made, up to that hit.
template <typename T>
inline bool any_in_block(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray,
                         std::uint64_t* stages, std::uint64_t* hits, std::uint8_t* log = nullptr) {
  switch (simd_mode()) {
#if OPRT_HAVE_AVX2
    case SimdMode::on: return detail::any_simd(m, first, end, ray, stages, hits, log);
#endif
    case SimdMode::check: return detail::any_checked(m, first, end, ray, stages, hits, log);
    default: return detail::any_scalar(m, first, end, ray, stages, hits, log);
  }
}

}  // namespace oprt
