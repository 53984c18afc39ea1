// Every option combines with every other (issue 20): --iu x --accel x --top x --sram (the
// unit's spheres fit its object memory, or it is a cache) x --kernel x --level, each
// rendering the reference's image bit for bit, and under the ideal architecture (the
// paper's: ideal bus, unbounded FIFOs, on-chip memory or a DRAM channel per unit) timing
// every unit exactly as `at` does at every level. One test case per unit model and
// acceleration, so that ctest runs them side by side; and the same with --replicate auto
// (hot spheres copied on several units, issue 27), whose copies each test only their share;
// and with --depth 0 and 5 (issue 29) on a scene that reflects and refracts
// (tests/data/scenes/whitted.json), each level issuing the reference's rays of every kind.
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <map>
#include <vector>

using namespace oprt::test;

namespace {
void every_combination(const std::string& iu, const std::string& accel, bool replicate = false, bool whitted = false) {
  const fs::path d = temp_dir("combinations_" + iu + "_" + accel + (replicate ? "_replicated" : "") +
                              (whitted ? "_whitted" : ""));
  // paper_room's frame 1; the Whitted scene's only frame, 0.
  const std::string frame = whitted ? "0" : "1";
  const std::string exr = whitted ? "frame_0000.exr" : "frame_0001.exr";
  const std::string file =
      whitted ? std::string(OPRT_SOURCE_DIR) + "/tests/data/scenes/whitted.json" : scene("paper_room.json");
  const std::string common = file + " --frames " + frame + " --resolution 20x15 --subdivide 2 --accel " + accel;
  int renders = 0;
  const std::vector<const char*> kernels =
      replicate ? std::vector<const char*>{"moller"} : std::vector<const char*>{"moller", "watertight"};
  // --depth: the scene's (paper_room reflects nothing), or 0 and 5 where rays bounce.
  const std::vector<std::string> depths = whitted ? std::vector<std::string>{" --depth 0", " --depth 5"}
                                                  : std::vector<std::string>{""};
  for (const char* kernel : kernels) {
    for (const std::string& depth : depths) {
      const std::string depth_name = depth.empty() ? "" : depth.substr(9);  // "0", "5"
      const fs::path ref = d / ("ref_" + std::string(kernel) + depth_name);
      REQUIRE(run_oprt("reference " + common + depth + " --kernel " + kernel + " --out " + ref.string()).status == 0);
      const auto reference = oprt::read_exr((ref / exr).string());
      const nlohmann::json reference_rays = stats(ref, "reference.json")["frames"][0]["rays"];
      if (whitted && depth == " --depth 5") CHECK(reference_rays["refraction"] > 0);
      for (const char* top : {"flat", "bvh"}) {
        // 64 MiB holds any unit's spheres; 4 KiB none of paper_room's, 256 bytes (one cache
        // set) none of the Whitted scene's: every memory is a cache.
        for (const char* sram : {"64M", whitted ? "256" : "4K"}) {
          nlohmann::json at;
          for (const char* level : {"at", "lt", "analytic"}) {
            const std::string what = std::string(kernel) + depth + " top " + top + " sram " + sram + " " + level;
            INFO(iu << " " << accel << " " << what);
            const fs::path out = d / (std::string(kernel) + depth_name + top + sram + level);
            const Result r = run_oprt("render " + common + depth + " --ius 6 --balance sa_n --iu " + iu +
                                      " --kernel " + kernel + " --top " + top + " --sram " + sram +
                                      " --level " + level + (replicate ? " --replicate auto" : "") + " --no-progress --out " + out.string());
            REQUIRE(r.status == 0);
            ++renders;
            CHECK(oprt::read_exr((out / exr).string()) == reference);
            const nlohmann::json f = stats(out)["frames"][0];
            for (const char* kind : {"primary", "shadow", "reflection", "refraction"})
              CHECK(f["rays"].value(kind, std::uint64_t{0}) == reference_rays[kind]);
            for (const auto& u : f["ius"]) CHECK(u["memory"]["cache"] == (std::string(sram) != "64M"));
            // Copies are made only where they fit: none into small memories that are caches
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
  }
  CHECK(renders == static_cast<int>(kernels.size() * depths.size()) * 2 * 2 * 3);
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
TEST_CASE("combinations: serial units, brute force, --depth 0 and 5", "[cli][combinations][whitted]") {
  every_combination("serial", "brute", false, true);
}
TEST_CASE("combinations: serial units, BVH, --depth 0 and 5", "[cli][combinations][whitted]") {
  every_combination("serial", "bvh", false, true);
}
TEST_CASE("combinations: pipelined units, brute force, --depth 0 and 5", "[cli][combinations][whitted]") {
  every_combination("pipelined", "brute", false, true);
}
TEST_CASE("combinations: pipelined units, BVH, --depth 0 and 5", "[cli][combinations][whitted]") {
  every_combination("pipelined", "bvh", false, true);
}
