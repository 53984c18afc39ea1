#include "geom/simd.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace oprt {

namespace {
int available(SimdMode m) { return static_cast<int>(simd_available() ? m : SimdMode::off); }
}  // namespace

namespace detail {

int simd_mode_from_environment() {
  const char* e = std::getenv("OPRT_SIMD");
  SimdMode m = SimdMode::on;
  if (e && std::strcmp(e, "off") == 0) m = SimdMode::off;
  else if (e && std::strcmp(e, "check") == 0) m = SimdMode::check;
  else if (e && *e && std::strcmp(e, "on") != 0) {
    std::fprintf(stderr, "oprt: environment variable OPRT_SIMD: unknown value \"%s\" (off, on or check)\n", e);
    std::exit(2);
  }
  // Threads that race here all read the same environment and store the same value.
  const int v = available(m);
  simd_mode_now.store(v, std::memory_order_relaxed);
  return v;
}

void simd_mismatch(const char* what, std::uint64_t where) {
  std::fprintf(stderr, "oprt: OPRT_SIMD=check: the SIMD and scalar kernels differ: %s (at %llu)\n", what,
               static_cast<unsigned long long>(where));
  std::abort();
}

}  // namespace detail

void set_simd_mode(SimdMode m) { detail::simd_mode_now.store(available(m), std::memory_order_relaxed); }

const char* to_string(SimdMode m) {
  switch (m) {
    case SimdMode::off: return "off";
    case SimdMode::on: return "on";
    case SimdMode::check: return "check";
  }
  return "?";
}

}  // namespace oprt
