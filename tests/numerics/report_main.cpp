// numerics_report: issue 6's hard cases as a table of failure counts per kernel x
// precision (scripts/numerics_report runs it; docs/results.md holds its output), then issue
// 29's secondary-ray cases (only those with --secondary).
#include "hard_cases.h"

#include <cstdio>
#include <string>

using namespace oprt;
using namespace oprt::numerics;

namespace {
const char* kKinds[] = {"leaks", "double hits", "sphere misses", "self hits", "wrong"};
std::uint64_t kind(const Outcome& o, int k) {
  const std::uint64_t v[] = {o.leaks, o.double_hits, o.sphere_misses, o.self_hits, o.wrong};
  return v[k];
}
}  // namespace

int main(int argc, char** argv) {
  // --secondary: only issue 29's tables (the secondary rays), not issue 6's.
  const bool only_secondary = argc > 1 && std::string(argv[1]) == "--secondary";
  if (!only_secondary) {
  std::printf("| case | failure | moller float | moller double | watertight float | watertight double |\n");
  std::printf("|---|---|---|---|---|---|\n");
  Outcome total[4];
  for (const HardCase& c : hard_cases()) {
    Outcome o[4];
    int i = 0;
    for (Kernel k : {Kernel::moller, Kernel::watertight})
      for (bool dbl : {false, true}) {
        o[i] = c.run(k, dbl);
        total[i] += o[i];
        ++i;
      }
    std::printf("| %s | judged rays | %llu | %llu | %llu | %llu |\n", c.name.c_str(), (unsigned long long)o[0].trials,
                (unsigned long long)o[1].trials, (unsigned long long)o[2].trials, (unsigned long long)o[3].trials);
    for (int k = 0; k < 5; ++k) {
      if (!kind(o[0], k) && !kind(o[1], k) && !kind(o[2], k) && !kind(o[3], k)) continue;
      std::printf("| | %s | %llu | %llu | %llu | %llu |\n", kKinds[k], (unsigned long long)kind(o[0], k),
                  (unsigned long long)kind(o[1], k), (unsigned long long)kind(o[2], k), (unsigned long long)kind(o[3], k));
    }
  }
  std::printf("| **all cases** | judged rays | %llu | %llu | %llu | %llu |\n", (unsigned long long)total[0].trials,
              (unsigned long long)total[1].trials, (unsigned long long)total[2].trials,
              (unsigned long long)total[3].trials);
  for (int k = 0; k < 5; ++k)
    std::printf("| | %s | %llu | %llu | %llu | %llu |\n", kKinds[k], (unsigned long long)kind(total[0], k),
                (unsigned long long)kind(total[1], k), (unsigned long long)kind(total[2], k),
                (unsigned long long)kind(total[3], k));
  const Outcome tf = textbook_sphere_case(false), td = textbook_sphere_case(true);
  std::printf("\nThe paper's textbook sphere test on \"tiny spheres far away\" (not used by the model): "
              "%llu of %llu rays missed in float, %llu of %llu in double.\n",
              (unsigned long long)tf.sphere_misses, (unsigned long long)tf.trials, (unsigned long long)td.sphere_misses,
              (unsigned long long)td.trials);
  for (bool coords : {false, true}) {
    std::printf("Image check, closed meshes 1e5 from the origin %s, 256x256, pixels inside the silhouette "
                "showing background / the far side:",
                coords ? "in their vertex coordinates" : "by their object transform");
    for (Kernel k : {Kernel::moller, Kernel::watertight})
      for (bool dbl : {false, true}) {
        const ImageCheck c = image_check(k, dbl, coords, 256);
        std::printf("%s %s %s %llu / %llu of %llu", k == Kernel::moller && !dbl ? "" : ",", to_string(k),
                    dbl ? "double" : "float", (unsigned long long)c.background_inside,
                    (unsigned long long)c.see_through, (unsigned long long)c.inside_pixels);
      }
    std::printf(".\n");
  }
  std::printf("Shadow rays started at the hit point itself, without the offset: self hits");
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (bool dbl : {false, true}) {
      const Outcome o = shadow_case_without_offset(k, dbl);
      std::printf("%s %s %s %llu of %llu", k == Kernel::moller && !dbl ? "" : ",", to_string(k), dbl ? "double" : "float",
                  (unsigned long long)o.self_hits, (unsigned long long)o.trials);
    }
  std::printf(".\n");
  }
  // Issue 29: reflection and refraction rays, each primary ray's tree to the depth bound.
  std::printf("\n| secondary case | count | moller float | moller double | watertight float | watertight double |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const char* kTreeRows[] = {"primary rays that hit", "reflection rays", "refraction rays", "rays at depth 5",
                             "total internal reflections", "self hits", "surface hits", "leaks",
                             "overshoots", "crossings"};
  auto tree_row = [](const TreeOutcome& o, int k) {
    const std::uint64_t v[] = {o.primaries, o.reflection, o.refraction, o.deepest, o.tir, o.self_hits,
                               o.surface_hits, o.leaks, o.overshoots, o.crossings};
    return v[k];
  };
  for (const SecondaryCase& c : secondary_cases()) {
    TreeOutcome o[4];
    int i = 0;
    for (Kernel k : {Kernel::moller, Kernel::watertight})
      for (bool dbl : {false, true}) o[i++] = c.run(k, dbl);
    for (int k = 0; k < 10; ++k)
      std::printf("| %s | %s | %llu | %llu | %llu | %llu |\n", k == 0 ? c.name.c_str() : "", kTreeRows[k],
                  (unsigned long long)tree_row(o[0], k), (unsigned long long)tree_row(o[1], k),
                  (unsigned long long)tree_row(o[2], k), (unsigned long long)tree_row(o[3], k));
  }
  for (const SecondaryCase& c : secondary_cases()) {
    std::printf("%s, every secondary ray started at its hit point without the offset: self / surface hits of "
                "secondary rays",
                c.name.c_str());
    for (Kernel k : {Kernel::moller, Kernel::watertight})
      for (bool dbl : {false, true}) {
        const TreeOutcome o = secondary_case_without_offset(c.name, k, dbl);
        std::printf("%s %s %s %llu / %llu of %llu", k == Kernel::moller && !dbl ? "" : ",", to_string(k),
                    dbl ? "double" : "float", (unsigned long long)o.self_hits, (unsigned long long)o.surface_hits,
                    (unsigned long long)(o.reflection + o.refraction));
      }
    std::printf(".\n");
  }
  return 0;
}
