// Every named hard case (hard_cases.cpp) through the scalar kernels and through the SIMD
// kernels: with OPRT_SIMD's check mode every block call and every sphere chunk of the case
// runs both and compares every output bit for bit (a difference aborts with a message),
// and the outcomes of the three modes are the same counts.
#include "hard_cases.h"

#include "geom/simd.h"

#include <catch2/catch.hpp>

using namespace oprt;
using namespace oprt::numerics;

namespace {
struct Mode {
  SimdMode before = simd_mode();
  explicit Mode(SimdMode m) { set_simd_mode(m); }
  ~Mode() { set_simd_mode(before); }
};

bool same(const Outcome& a, const Outcome& b) {
  return a.trials == b.trials && a.leaks == b.leaks && a.double_hits == b.double_hits &&
         a.sphere_misses == b.sphere_misses && a.self_hits == b.self_hits && a.wrong == b.wrong;
}

template <typename Run>
void in_every_mode(Run&& run, bool traces = true) {
  if (!simd_available()) WARN("this build has no SIMD kernels (no AVX2): every mode runs the scalar ones");
  const auto before = simd_checks();
  Outcome off, check, on;
  {
    const Mode m(SimdMode::off);
    off = run();
  }
  {
    const Mode m(SimdMode::check);
    check = run();
  }
  {
    const Mode m(SimdMode::on);
    on = run();
  }
  CHECK(same(off, check));
  CHECK(same(off, on));
  if (simd_available() && traces) CHECK(simd_checks() > before);  // the calls were compared
}

void compare_case(const std::string& name) {
  const HardCase& c = hard_case(name);
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      INFO(name << ", " << to_string(k) << ", " << (dbl ? "double" : "float"));
      in_every_mode([&] { return c.run(k, dbl); }, name != "invalid transforms");  // that one only sets up
    }
}
}  // namespace

TEST_CASE("simd = scalar: shared edges", "[numerics][simd]") { compare_case("shared edges"); }
TEST_CASE("simd = scalar: shared vertices", "[numerics][simd]") { compare_case("shared vertices"); }
TEST_CASE("simd = scalar: through", "[numerics][simd]") { compare_case("through"); }
TEST_CASE("simd = scalar: far from origin", "[numerics][simd]") { compare_case("far from origin"); }
TEST_CASE("simd = scalar: far in coordinates", "[numerics][simd]") { compare_case("far in coordinates"); }
TEST_CASE("simd = scalar: scaled", "[numerics][simd]") { compare_case("scaled"); }
TEST_CASE("simd = scalar: grazing", "[numerics][simd]") { compare_case("grazing"); }
TEST_CASE("simd = scalar: axis-aligned", "[numerics][simd]") { compare_case("axis-aligned"); }
TEST_CASE("simd = scalar: camera inside", "[numerics][simd]") { compare_case("camera inside"); }
TEST_CASE("simd = scalar: tiny spheres far away", "[numerics][simd]") { compare_case("tiny spheres far away"); }
TEST_CASE("simd = scalar: shadow rays", "[numerics][simd]") { compare_case("shadow rays"); }
TEST_CASE("simd = scalar: near-singular transforms", "[numerics][simd]") { compare_case("near-singular transforms"); }
TEST_CASE("simd = scalar: invalid transforms", "[numerics][simd]") { compare_case("invalid transforms"); }
TEST_CASE("simd = scalar: degenerate triangles", "[numerics][simd]") { compare_case("degenerate triangles"); }
TEST_CASE("simd = scalar: the list above is every hard case", "[numerics][simd]") { CHECK(hard_cases().size() == 14); }

TEST_CASE("simd = scalar: shadow rays without their offset", "[numerics][simd]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      INFO(to_string(k) << ", " << (dbl ? "double" : "float"));
      in_every_mode([&] { return shadow_case_without_offset(k, dbl); });
    }
}

TEST_CASE("simd = scalar: the image-level check renders the same", "[numerics][simd]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true})
      for (bool in_coordinates : {false, true}) {
        INFO(to_string(k) << ", " << (dbl ? "double" : "float") << (in_coordinates ? ", in coordinates" : ""));
        ImageCheck a, b;
        {
          const Mode m(SimdMode::off);
          a = image_check(k, dbl, in_coordinates, 48);
        }
        {
          const Mode m(SimdMode::check);
          b = image_check(k, dbl, in_coordinates, 48);
        }
        CHECK(a.inside_pixels == b.inside_pixels);
        CHECK(a.background_inside == b.background_inside);
        CHECK(a.see_through == b.see_through);
        CHECK(a.inside_pixels > 0);
      }
}
