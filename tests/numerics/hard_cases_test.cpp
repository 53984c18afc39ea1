// Issue 6's named hard cases, each per kernel x precision (hard_cases.cpp builds them and
// counts the outcomes against double-precision oracles). Asserted: the watertight kernel
// never leaks and, with its ownership rule, never hits twice at one crossing; no kernel
// misses a bounding sphere a ray enters, self-shadows, or gets anything else wrong.
// Moller-Trumbore's leaks and double hits are counted, not asserted (scripts/numerics_report).
// Then issue 29's secondary-ray cases (reflection and refraction rays to depth 5).
#include "hard_cases.h"

#include "geom/affine.h"
#include "ref/shading.h"

#include <catch2/catch.hpp>

#include <limits>

using namespace oprt;
using namespace oprt::numerics;

namespace {
Outcome check_case(const std::string& name, Kernel k, bool dbl) {
  const HardCase& c = hard_case(name);
  const Outcome o = c.run(k, dbl);
  INFO(name << ", " << to_string(k) << ", " << (dbl ? "double" : "float") << ": " << o.trials << " judged, "
            << o.leaks << " leaks, " << o.double_hits << " double hits, " << o.sphere_misses << " sphere misses, "
            << o.self_hits << " self hits, " << o.wrong << " wrong");
  CHECK(o.trials > 0);
  if (k == Kernel::watertight) {
    CHECK(o.leaks == 0);
    if (c.double_hits_asserted) CHECK(o.double_hits == 0);
  }
  CHECK(o.sphere_misses == 0);
  CHECK(o.self_hits == 0);
  CHECK(o.wrong == 0);
  return o;
}

void check_case(const std::string& name) {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) check_case(name, k, dbl);
}
}  // namespace

TEST_CASE("hard case: shared edges", "[numerics]") { check_case("shared edges"); }
TEST_CASE("hard case: shared vertices", "[numerics]") { check_case("shared vertices"); }
TEST_CASE("hard case: through", "[numerics]") { check_case("through"); }
TEST_CASE("hard case: far from origin", "[numerics]") { check_case("far from origin"); }
TEST_CASE("hard case: scaled", "[numerics]") { check_case("scaled"); }
TEST_CASE("hard case: grazing", "[numerics]") { check_case("grazing"); }
TEST_CASE("hard case: axis-aligned", "[numerics]") { check_case("axis-aligned"); }
TEST_CASE("hard case: camera inside", "[numerics]") { check_case("camera inside"); }
TEST_CASE("hard case: tiny spheres far away", "[numerics]") { check_case("tiny spheres far away"); }
TEST_CASE("hard case: shadow rays", "[numerics]") { check_case("shadow rays"); }
TEST_CASE("hard case: near-singular transforms", "[numerics]") { check_case("near-singular transforms"); }
TEST_CASE("hard case: invalid transforms", "[numerics]") { check_case("invalid transforms"); }
TEST_CASE("hard case: degenerate triangles", "[numerics]") { check_case("degenerate triangles"); }

// The cases have teeth: what they catch happens without the measures under test.
TEST_CASE("hard cases are real: Moller-Trumbore leaks at shared edges and vertices in float", "[numerics]") {
  CHECK(hard_case("shared edges").run(Kernel::moller, false).leaks > 0);
  CHECK(hard_case("shared vertices").run(Kernel::moller, false).leaks > 0);
  CHECK(hard_case("axis-aligned").run(Kernel::moller, false).double_hits > 0);  // exact edge hits occur
}

TEST_CASE("hard cases are real: shadow rays without their offset shadow themselves", "[numerics]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight}) {
    INFO(to_string(k));
    const Outcome o = shadow_case_without_offset(k, false);
    CHECK(o.self_hits > o.trials / 10);
  }
}

TEST_CASE("hard cases are real: the textbook sphere test misses tiny spheres far away in float", "[numerics]") {
  const Outcome o = textbook_sphere_case(false);
  CHECK(o.sphere_misses > o.trials / 20);
}

// Issue 29: reflection and refraction rays, each primary ray's tree to depth 5 through the
// shader and the engine's traversal (hard_cases.h says how each ray is judged). Asserted for
// both kernels in both precisions: no ray hits its own triangle (a self hit) or, where exact
// geometry allows none, the surface it leaves (a surface hit); the watertight kernel never
// leaks. Overshoots and crossings are counted, not asserted (docs/results.md).
namespace {
TreeOutcome check_secondary(const std::string& name, Kernel k, bool dbl) {
  const TreeOutcome o = secondary_case(name).run(k, dbl);
  INFO(name << ", " << to_string(k) << ", " << (dbl ? "double" : "float") << ": " << o.primaries << " primary, "
            << o.reflection << " reflection, " << o.refraction << " refraction rays, " << o.deepest << " at depth "
            << kSecondaryDepth << ", " << o.tir << " TIR; " << o.self_hits << " self hits, " << o.surface_hits
            << " surface hits, " << o.leaks << " leaks, " << o.overshoots << " overshoots, " << o.crossings
            << " crossings");
  CHECK(o.primaries > 0);
  CHECK(o.deepest > 0);  // some trees reach the depth bound
  CHECK(o.self_hits == 0);
  CHECK(o.surface_hits == 0);
  if (k == Kernel::watertight) CHECK(o.leaks == 0);
  return o;
}
}  // namespace

TEST_CASE("secondary case: glass sphere", "[numerics]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      const TreeOutcome o = check_secondary("glass sphere", k, dbl);
      // Rays enter and leave (two refractions per primary ray at least, for most) and meet
      // total internal reflection (reflect is 0: every reflection ray is one).
      CHECK(o.refraction > o.primaries);
      CHECK(o.tir > 0);
      CHECK(o.reflection == o.tir);
      if (dbl) CHECK(o.overshoots == 0);
    }
}

TEST_CASE("secondary case: facing mirrors", "[numerics]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      const TreeOutcome o = check_secondary("facing mirrors", k, dbl);
      CHECK(o.refraction == 0);
      CHECK(o.reflection > 4 * o.primaries);  // most bounce to the bound
    }
}

TEST_CASE("secondary case: closed meshes, reflect and transmit", "[numerics]") {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      const TreeOutcome o = check_secondary("closed meshes, reflect and transmit", k, dbl);
      CHECK(o.reflection > 0);
      CHECK(o.refraction > 0);
      if (dbl) CHECK(o.overshoots + o.crossings == 0);
    }
}

TEST_CASE("hard cases are real: secondary rays without their offset hit their own triangle", "[numerics]") {
  for (const SecondaryCase& c : secondary_cases())
    for (Kernel k : {Kernel::moller, Kernel::watertight}) {
      INFO(c.name << ", " << to_string(k));
      const TreeOutcome o = secondary_case_without_offset(c.name, k, false);
      CHECK(o.self_hits > (o.reflection + o.refraction) / 10);
    }
}

// The offset's bound per axis (ref/shading.cpp): a slab scaled by (1, 1e-2, 1e2), its top
// face the local plane y = 1 (triangle (-1, 1, -1), (1, 1, -1), (0, 1, 1)), left at the
// local point (0, 1, 0), world (0, 0.01, 0), along +y. By hand: e_y = |L^-1_yy p_y| +
// |t^-1_y| + the vertex magnitudes = 100 * 0.01 + 0 + (1 + 2) = 4; along n = +y the bound
// is |M_yy| e_y + |p_y| = 0.01 * 4 + 0.01 = 0.05, so the offset is 16 eps 0.05. The
// isotropic bound, stretch(M) (|L^-1| |p| + vertices) + |p| = 100 (1 + 3) + 0.01, would be
// 8000 times that.
TEST_CASE("offset_origin bounds the rounding per axis under an anisotropic map", "[numerics]") {
  const Placement pl = *make_placement(scale({1, 1e-2, 1e2}));
  const Vec3d v0(-1, 1, -1), v1(1, 1, -1), v2(0, 1, 1), p(0, 0.01, 0), n(0, 1, 0);
  for (bool dbl : {false, true}) {
    const double eps = dbl ? std::numeric_limits<double>::epsilon() : std::numeric_limits<float>::epsilon();
    const double want = 16 * eps * 0.05;
    const Vec3d o = dbl ? offset_origin<double>(Kernel::moller, p, n, n, pl, v0, v1, v2)
                        : offset_origin<float>(Kernel::moller, p, n, n, pl, v0, v1, v2);
    INFO((dbl ? "double" : "float") << ": offset " << o.y - 0.01 << ", bound " << want);
    CHECK(o.x == 0);
    CHECK(o.z == 0);
    CHECK(o.y - 0.01 >= want - 2 * eps * 0.01);
    CHECK(o.y - 0.01 <= want + 2 * eps * 0.01);  // and the rounding of o.y away from the surface
  }
}
