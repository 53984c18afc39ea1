// Every option combines with every other (issue 20): --iu x --accel x --top x --sram (the
// unit's spheres fit its object memory, or it is a cache) x --kernel x --level, each
// rendering the reference's image bit for bit, and under the ideal architecture (the
// paper's: ideal bus, unbounded FIFOs, on-chip memory or a DRAM channel per unit) timing
// every unit exactly as `at` does at every level. One test case per unit model and
// acceleration, so that ctest runs them side by side; and the same with --replicate auto
// (hot spheres copied on several units, issue 27), whose copies each test only their share.
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <map>
#include <vector>

using namespace oprt::test;

namespace {
void every_combination(const std::string& iu, const std::string& accel, bool replicate = false) {
  const fs::path d = temp_dir("combinations_" + iu + "_" + accel + (replicate ? "_replicated" : ""));
  const std::string common = scene("paper_room.json") + " --frames 1 --resolution 20x15 --subdivide 2 --accel " + accel;
  int renders = 0;
  const std::vector<const char*> kernels =
      replicate ? std::vector<const char*>{"moller"} : std::vector<const char*>{"moller", "watertight"};
  for (const char* kernel : kernels) {
    const fs::path ref = d / ("ref_" + std::string(kernel));
    REQUIRE(run_oprt("reference " + common + " --kernel " + kernel + " --out " + ref.string()).status == 0);
    const auto reference = oprt::read_exr((ref / "frame_0001.exr").string());
    for (const char* top : {"flat", "bvh"}) {
      // 64 MiB holds any unit's spheres; 4 KiB none of them: every memory is a cache.
      for (const char* sram : {"64M", "4K"}) {
        nlohmann::json at;
        for (const char* level : {"at", "lt", "analytic"}) {
          const std::string what = std::string(kernel) + " top " + top + " sram " + sram + " " + level;
          INFO(iu << " " << accel << " " << what);
          const fs::path out = d / (std::string(kernel) + top + sram + level);
          const Result r = run_oprt("render " + common + " --ius 6 --balance sa_n --iu " + iu + " --kernel " + kernel +
                                    " --top " + top + " --sram " + sram + " --level " + level +
                                    (replicate ? " --replicate auto" : "") + " --no-progress --out " + out.string());
          REQUIRE(r.status == 0);
          ++renders;
          CHECK(oprt::read_exr((out / "frame_0001.exr").string()) == reference);
          const nlohmann::json f = stats(out)["frames"][0];
          for (const auto& u : f["ius"]) CHECK(u["memory"]["cache"] == (std::string(sram) == "4K"));
          // Copies are made only where they fit: none into 4 KiB memories that are caches
          // already (they are within capacity only in the 64 MiB case).
          CHECK(f.contains("replicas") == replicate);
          if (replicate && std::string(sram) == "64M") CHECK(!f["replicas"]["copies"].empty());
          if (std::string(level) == "at") {
            at = f;
            continue;
          }
          CHECK(f["makespan_cycles"] == at["makespan_cycles"]);
          CHECK(f["busy_cycles"] == at["busy_cycles"]);
          for (std::size_t u = 0; u < f["ius"].size(); ++u) {
            CHECK(f["ius"][u]["cycles"] == at["ius"][u]["cycles"]);
            CHECK(f["ius"][u]["memory"] == at["ius"][u]["memory"]);
            CHECK(f["ius"][u]["work"] == at["ius"][u]["work"]);
            if (iu == "pipelined") CHECK(f["ius"][u]["pipeline"] == at["ius"][u]["pipeline"]);
          }
        }
      }
    }
  }
  CHECK(renders == static_cast<int>(kernels.size()) * 2 * 2 * 3);
}
}  // namespace

TEST_CASE("combinations: serial units, brute force", "[cli][combinations]") { every_combination("serial", "brute"); }
TEST_CASE("combinations: serial units, BVH", "[cli][combinations]") { every_combination("serial", "bvh"); }
TEST_CASE("combinations: pipelined units, brute force", "[cli][combinations]") { every_combination("pipelined", "brute"); }
TEST_CASE("combinations: pipelined units, BVH", "[cli][combinations]") { every_combination("pipelined", "bvh"); }
TEST_CASE("combinations: serial units, brute force, replicated", "[cli][combinations]") {
  every_combination("serial", "brute", true);
}
TEST_CASE("combinations: serial units, BVH, replicated", "[cli][combinations]") { every_combination("serial", "bvh", true); }
TEST_CASE("combinations: pipelined units, brute force, replicated", "[cli][combinations]") {
  every_combination("pipelined", "brute", true);
}
TEST_CASE("combinations: pipelined units, BVH, replicated", "[cli][combinations]") {
  every_combination("pipelined", "bvh", true);
}
