// SIMD packs for the kernels of geom/simd_kernels.h, and the switch between those kernels and the
// scalar ones. A pack is W lanes of T in one AVX2 register: 8 floats or 4 doubles. Only what
// the kernels need: IEEE +, -, *, /, negation, the comparisons C++ writes, masks as lane bits.
//
// Every operation here is one IEEE operation per lane, rounded exactly as the scalar
// operation on that lane's operands rounds (round to nearest even, the same MXCSR as scalar
// SSE code): a kernel that performs, per lane, the scalar kernel's operations in the
// scalar kernel's order gets the scalar kernel's bits. Nothing fuses: with
// -ffp-contract=off the compiler emits no FMA for a multiply followed by an add, written
// with intrinsics or not (tests/numerics checks the build; objdump finds no vfmadd in the
// kernels). Comparisons use the ordered, quiet predicates for <, <=, >, >=, == and the
// unordered one for != so that NaN lanes compare as C++ compares them.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>

#if defined(__AVX2__)
#include <immintrin.h>
#define OPRT_HAVE_AVX2 1
#else
#define OPRT_HAVE_AVX2 0
#endif

// The chunk kernels are inlined into their block loops whatever the compiler's size
// heuristics say: a chunk's result lives in registers, not in memory.
#define OPRT_SIMD_INLINE inline __attribute__((always_inline))

namespace oprt {

// Which kernels the block and sphere functions run. off: the scalar kernels (the
// reference definition); on: the SIMD kernels when the build has them (AVX2), the scalar
// ones otherwise; check: both, compared field by field on every call, aborting with a
// message at the first difference (slow; for tests and scripts/simd_check).
enum class SimdMode : int { off = 0, on = 1, check = 2 };

// The build has the SIMD kernels (compiled with AVX2, e.g. OPRT_NATIVE=ON on this machine).
constexpr bool simd_available() { return OPRT_HAVE_AVX2 != 0; }

// The mode in force: set_simd_mode's, else the environment variable OPRT_SIMD (off, on,
// check; unset: on), read once; an unknown value is an error (message, exit status 2).
// Without AVX2, on and check mean off. Set it before rendering starts: the kernels read it
// on every call, from any thread.
namespace detail {
inline std::atomic<int> simd_mode_now{-1};  // -1: not read from the environment yet
int simd_mode_from_environment();
// check mode: report a difference between the scalar and the SIMD kernel, and abort.
[[noreturn]] void simd_mismatch(const char* what, std::uint64_t where);
inline std::atomic<std::uint64_t> simd_checks_made{0};
inline void simd_checked() { simd_checks_made.fetch_add(1, std::memory_order_relaxed); }
}  // namespace detail

// How many calls check mode has compared so far (block calls and sphere chunks).
inline std::uint64_t simd_checks() { return detail::simd_checks_made.load(std::memory_order_relaxed); }

inline SimdMode simd_mode() {
  const int m = detail::simd_mode_now.load(std::memory_order_relaxed);
  return static_cast<SimdMode>(m >= 0 ? m : detail::simd_mode_from_environment());
}
void set_simd_mode(SimdMode m);
const char* to_string(SimdMode m);

// Lane count of the SIMD kernels per precision (also the chunk of spheres tested at once).
template <typename T>
constexpr unsigned kLanes = 32 / sizeof(T);

// Bit i set in the low `n` bits: lanes 0 .. n-1 of a chunk.
inline unsigned lanes_below(unsigned n) { return n >= 32 ? ~0u : (1u << n) - 1; }

// Each of the low 8 (or 4) bits of m to a byte 0 or 1, lane i in byte i (little-endian
// memory order): the exit-stage log is the sum of the stage masks spread this way.
inline std::uint64_t spread_bits(unsigned m) {
#if defined(__BMI2__)
  return _pdep_u64(m, 0x0101010101010101ull);
#else
  std::uint64_t r = 0;
  for (int i = 0; i < 8; ++i) r |= static_cast<std::uint64_t>((m >> i) & 1u) << (8 * i);
  return r;
#endif
}

#if OPRT_HAVE_AVX2
namespace simd {

template <typename T>
struct Pack;

// A lane mask: all ones (true) or all zeros per lane, in the pack's own register type.
template <typename T>
struct Mask {
  typename Pack<T>::Reg m;
};

template <>
struct Pack<float> {
  using Reg = __m256;
  static constexpr unsigned W = 8;
  Reg v;
  static Pack splat(float x) { return {_mm256_set1_ps(x)}; }
  static Pack load(const float* p) { return {_mm256_loadu_ps(p)}; }
  // Lanes >= n read as 0 and touch no memory.
  static Pack load(const float* p, unsigned n) {
    if (n >= W) return load(p);
    const __m256i idx = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i keep = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(n)), idx);
    return {_mm256_maskload_ps(p, keep)};
  }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
};

template <>
struct Pack<double> {
  using Reg = __m256d;
  static constexpr unsigned W = 4;
  Reg v;
  static Pack splat(double x) { return {_mm256_set1_pd(x)}; }
  static Pack load(const double* p) { return {_mm256_loadu_pd(p)}; }
  static Pack load(const double* p, unsigned n) {
    if (n >= W) return load(p);
    const __m256i idx = _mm256_setr_epi64x(0, 1, 2, 3);
    const __m256i keep = _mm256_cmpgt_epi64(_mm256_set1_epi64x(static_cast<long long>(n)), idx);
    return {_mm256_maskload_pd(p, keep)};
  }
  void store(double* p) const { _mm256_storeu_pd(p, v); }
};

using F = Pack<float>;
using D = Pack<double>;

inline F operator+(F a, F b) { return {_mm256_add_ps(a.v, b.v)}; }
inline F operator-(F a, F b) { return {_mm256_sub_ps(a.v, b.v)}; }
inline F operator*(F a, F b) { return {_mm256_mul_ps(a.v, b.v)}; }
inline F operator/(F a, F b) { return {_mm256_div_ps(a.v, b.v)}; }
inline F operator-(F a) { return {_mm256_xor_ps(a.v, _mm256_set1_ps(-0.0f))}; }  // exact, as scalar negation
inline Mask<float> operator<(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline Mask<float> operator<=(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
inline Mask<float> operator>(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline Mask<float> operator==(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline Mask<float> operator!=(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NEQ_UQ)}; }
inline Mask<float> operator|(Mask<float> a, Mask<float> b) { return {_mm256_or_ps(a.m, b.m)}; }
inline Mask<float> operator&(Mask<float> a, Mask<float> b) { return {_mm256_and_ps(a.m, b.m)}; }
inline unsigned bits(Mask<float> a) { return static_cast<unsigned>(_mm256_movemask_ps(a.m)); }
inline F select(Mask<float> m, F a, F b) { return {_mm256_blendv_ps(b.v, a.v, m.m)}; }

inline D operator+(D a, D b) { return {_mm256_add_pd(a.v, b.v)}; }
inline D operator-(D a, D b) { return {_mm256_sub_pd(a.v, b.v)}; }
inline D operator*(D a, D b) { return {_mm256_mul_pd(a.v, b.v)}; }
inline D operator/(D a, D b) { return {_mm256_div_pd(a.v, b.v)}; }
inline D operator-(D a) { return {_mm256_xor_pd(a.v, _mm256_set1_pd(-0.0))}; }
inline Mask<double> operator<(D a, D b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ)}; }
inline Mask<double> operator<=(D a, D b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LE_OQ)}; }
inline Mask<double> operator>(D a, D b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_GT_OQ)}; }
inline Mask<double> operator==(D a, D b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_EQ_OQ)}; }
inline Mask<double> operator!=(D a, D b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_NEQ_UQ)}; }
inline Mask<double> operator|(Mask<double> a, Mask<double> b) { return {_mm256_or_pd(a.m, b.m)}; }
inline Mask<double> operator&(Mask<double> a, Mask<double> b) { return {_mm256_and_pd(a.m, b.m)}; }
inline unsigned bits(Mask<double> a) { return static_cast<unsigned>(_mm256_movemask_pd(a.m)); }
inline D select(Mask<double> m, D a, D b) { return {_mm256_blendv_pd(b.v, a.v, m.m)}; }

// Lane i of a pack, for the scalar work on the few lanes that need it.
template <typename T>
struct Lanes {
  alignas(32) T x[Pack<T>::W];
  explicit Lanes(Pack<T> p) { p.store(x); }
  T operator[](unsigned i) const { return x[i]; }
};

}  // namespace simd
#endif  // OPRT_HAVE_AVX2

}  // namespace oprt
