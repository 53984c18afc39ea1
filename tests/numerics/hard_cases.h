// The named hard cases of numerical robustness (issue 6), each run per kernel and
// precision through the code the engine runs: meshes placed by an object transform, world
// spheres and world -> local matrices from the frame set-up, rays carried into the local
// frame in T, and every triangle tested through the block functions (the one dispatch
// point). Outcomes are counts, judged against double-precision oracles that never call
// the kernels. tests/numerics asserts on them; scripts/numerics_report prints them.
#pragma once

#include "geom/kernel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt::numerics {

struct Outcome {
  std::uint64_t trials = 0;         // rays (or items) the oracle could judge
  std::uint64_t leaks = 0;          // a crossing of a closed mesh with no hit (entry or exit)
  std::uint64_t double_hits = 0;    // hits beyond one at one crossing
  std::uint64_t sphere_misses = 0;  // a bounding sphere rejected for a ray that enters it
  std::uint64_t self_hits = 0;      // shadow rays occluded by the convex surface they leave
  std::uint64_t wrong = 0;          // other wrong answers (see each case)

  Outcome& operator+=(const Outcome& o);
};

struct HardCase {
  std::string name;
  std::string what;  // what is aimed at, and what `wrong` counts
  // Rays aimed at shared edges and vertices may legitimately hit two triangles where
  // the mesh is only nearly planar (grazing rays): double hits are then not asserted.
  bool double_hits_asserted = true;
  Outcome (*run_float)(Kernel);
  Outcome (*run_double)(Kernel);
  Outcome run(Kernel k, bool dbl) const { return dbl ? run_double(k) : run_float(k); }
};

const std::vector<HardCase>& hard_cases();
const HardCase& hard_case(const std::string& name);  // throws std::out_of_range

// The "tiny spheres far away" case run with the paper's textbook sphere test, which the
// model does not use: its misses show why.
Outcome textbook_sphere_case(bool dbl);
// The image-level check: a closed mesh (a UV sphere, then a subdivided box) placed 1e5
// from the origin, by its object transform or (in_coordinates) in its own vertex
// coordinates, rendered by the reference renderer at size x size; the pixels whose
// double-precision camera ray passes clearly inside it, how many of those show the
// background, and how many show the mesh's far side (the ray leaked through its front).
struct ImageCheck {
  std::uint64_t inside_pixels = 0, background_inside = 0, see_through = 0;
};
ImageCheck image_check(Kernel k, bool dbl, bool in_coordinates, int size);

// The "shadow rays" case with origins at the hit points themselves, no offset.
Outcome shadow_case_without_offset(Kernel k, bool dbl);

// Issue 29: Whitted ray trees on hard geometry. Each primary ray's tree is traced to depth
// 5 through the shader (Shader::shade spawns the reflection and refraction rays, with their
// origins from offset_origin) and the engine's traversal (trace_nearest over every sphere),
// and every reflection and refraction ray is judged by where its nearest hit lies:
// - a self hit: on the parent's own triangle. A ray that leaves a triangle's plane cannot
//   meet that plane again, so its exact distance to it is never positive: any t the kernel
//   reports there is rounding, whatever its size;
// - a surface hit: elsewhere on the surface it leaves where exact geometry allows none: any
//   triangle of a planar mirror, any triangle of a closed convex mesh for a ray leaving it
//   outward, or, for a ray entering (or staying inside) a closed convex mesh, a hit before
//   half the oracle's distance to where the ray leaves the mesh (double, never a kernel);
// - an overshoot: a ray entering (or staying inside) a closed convex mesh whose origin lies
//   outside it by more than the origin's own rounding to T: the offset pushed the origin
//   through to the far side (the ray then misses the surface it should leave by); an origin
//   within that rounding of the surface is not judged;
// - a crossing: such a ray whose origin lies clearly inside, and whose T-rounded local
//   origin (what the kernel sees) lies outside: the world -> local transform in T carried it
//   across another face near an edge. Neither of these is judged further;
// - a leak: a ray entering a closed convex mesh that hits nothing (Moller's cracks; the
//   watertight kernel has none).
// Shadow rays are judged by the "shadow rays" case above.
struct TreeOutcome {
  std::uint64_t primaries = 0;   // primary rays that hit
  std::uint64_t reflection = 0;  // reflection rays judged
  std::uint64_t refraction = 0;  // refraction rays judged
  std::uint64_t deepest = 0;     // of those, rays at the depth bound
  std::uint64_t tir = 0;         // hits where the refraction turned into total internal reflection
  std::uint64_t self_hits = 0;
  std::uint64_t surface_hits = 0;
  std::uint64_t leaks = 0;
  std::uint64_t overshoots = 0;
  std::uint64_t crossings = 0;
  double self_t_max = 0;  // the largest t of a self or surface hit (0: none)

  TreeOutcome& operator+=(const TreeOutcome& o);
};

struct SecondaryCase {
  std::string name;
  std::string what;
  TreeOutcome (*run_float)(Kernel);
  TreeOutcome (*run_double)(Kernel);
  TreeOutcome run(Kernel k, bool dbl) const { return dbl ? run_double(k) : run_float(k); }
};

const std::vector<SecondaryCase>& secondary_cases();
const SecondaryCase& secondary_case(const std::string& name);  // throws std::out_of_range
// The depth bound the secondary cases trace to.
constexpr int kSecondaryDepth = 5;
// A secondary case with every reflection and refraction ray started at its hit point
// itself (rounded to T), no offset: the control that shows the cases are hard.
TreeOutcome secondary_case_without_offset(const std::string& name, Kernel k, bool dbl);

}  // namespace oprt::numerics
