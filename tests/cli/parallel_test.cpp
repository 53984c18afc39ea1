// What makes oprt fast must not change what it reports: any number of threads gives the same
// bytes, and intersection units that run ahead of simulation time (where nothing can observe
// them) give exactly what units waiting out every ray give, waveforms included.
#include "cli_util.h"

#include <catch2/catch.hpp>

using namespace oprt::test;

namespace {

void check_same_files(const fs::path& a, const fs::path& b, const std::vector<std::string>& names) {
  for (const std::string& n : names) {
    INFO(n);
    REQUIRE(fs::exists(a / n));
    CHECK(bytes_of(a / n) == bytes_of(b / n));
  }
}

// `differing`: header keys the two runs were asked to differ in.
void check_same_stats(const fs::path& a, const fs::path& b, const std::string& file,
                      const std::vector<std::string>& differing = {}) {
  nlohmann::json x = without_wall_clock(stats(a, file)), y = without_wall_clock(stats(b, file));
  for (const std::string& k : differing) {
    x.erase(k);
    y.erase(k);
  }
  CHECK(x == y);
  CHECK(x.dump().size() > 500);  // a real statistics file, not two empty ones
}

}  // namespace

TEST_CASE("cli: reference with 1, 2 and 3 threads writes the same bytes", "[cli][threads]") {
  const fs::path d = temp_dir("threads_reference");
  for (int n : {1, 2, 3}) {
    const Result r = run_oprt("reference " + scene("paper_polygons.json") + " --frames 0:1 --resolution 40x40 --threads " +
                              std::to_string(n) + " --out " + (d / std::to_string(n)).string());
    REQUIRE(r.status == 0);
  }
  // Triangle tests are counted per sphere by each thread and summed: the totals are those of
  // one thread, and (4 spheres x 40 x 40 primary rays at least) not trivially zero.
  CHECK(stats(d / "1", "reference.json")["frames"][0]["work"]["primary"]["sphere_tests"] == 32 * 40 * 40);
  CHECK(stats(d / "3", "reference.json")["threads"] == 3);
  for (int n : {2, 3}) {
    check_same_files(d / "1", d / std::to_string(n), {"frame_0000.exr", "frame_0000.png", "frame_0001.exr"});
    check_same_stats(d / "1", d / std::to_string(n), "reference.json");
  }
}

TEST_CASE("cli: render at every level with 1, 2 and 3 threads writes the same bytes", "[cli][threads]") {
  const fs::path d = temp_dir("threads_render");
  for (const std::string level : {"at", "lt", "analytic"}) {
    for (int n : {1, 2, 3}) {
      const Result r = run_oprt("render " + scene("paper_room.json") + " --ius 8 --frames 0:1 --resolution 40x40 --level " +
                                level + " --threads " + std::to_string(n) + " --no-progress --out " +
                                (d / (level + std::to_string(n))).string());
      REQUIRE(r.status == 0);
    }
    for (const char* n : {"2", "3"}) {
      INFO(level << " with " << n << " threads");
      check_same_files(d / (level + "1"), d / (level + n), {"frame_0000.exr", "frame_0001.png", "stats.csv"});
      check_same_stats(d / (level + "1"), d / (level + n), "stats.json");
    }
  }
}

TEST_CASE("cli: compare with 1, 2 and 3 threads prints the same bytes", "[cli][threads]") {
  const fs::path d = temp_dir("threads_compare");
  REQUIRE(run_oprt("reference " + scene("paper_room.json") + " --frames 0 --resolution 64x48 --out " + (d / "f").string()).status == 0);
  REQUIRE(run_oprt("reference " + scene("paper_room.json") + " --frames 0 --resolution 64x48 --precision double --out " +
                   (d / "d").string()).status == 0);
  const std::string args = "compare " + (d / "f" / "frame_0000.exr").string() + " " + (d / "d" / "frame_0000.exr").string();
  const Result one = run_oprt(args + " --threads 1");
  REQUIRE(one.status == 0);
  CHECK(nlohmann::json::parse(one.output)["pixels"] == 64 * 48);
  CHECK(run_oprt(args + " --threads 2").output == one.output);
  CHECK(run_oprt(args + " --threads 3").output == one.output);
}

TEST_CASE("cli: --threads takes a positive count", "[cli][threads]") {
  for (const char* bad : {"0", "-2", "many"}) {
    const Result r = run_oprt("reference " + scene("paper_room.json") + " --threads " + bad);
    CHECK(r.status == 2);
    CHECK(r.output.find("--threads") != std::string::npos);
  }
}

namespace {
// The same run three times: units running ahead (the default where nothing can observe
// them), running ahead but made to wait often by a tiny trace buffer (vcd_writer.h), and
// every unit waiting out each ray in simulated time.
void check_running_ahead_is_exact(const std::string& name, const std::string& arch_json, const std::string& extra) {
  const fs::path d = temp_dir("ahead_" + name);
  for (const std::string mode : {"ahead", "tight", "sync"}) {
    std::string arch = arch_json;
    if (mode == "sync") arch.insert(arch.size() - 1, ", \"sync_every_ray\": true");
    std::ofstream(d / (mode + ".json")) << arch;
    const Result r = run_oprt("render " + scene("paper_room.json") + " --arch " + (d / (mode + ".json")).string() +
                              " --frames 0:1 --resolution 40x40 --no-progress " + extra + " --vcd " +
                              (d / mode / "trace.vcd").string() + " --out " + (d / mode).string() +
                              (mode == "tight" ? " --trace-buffer 64" : ""));
    REQUIRE(r.status == 0);
  }
  check_same_stats(d / "ahead", d / "sync", "stats.json", {"arch"});
  check_same_files(d / "ahead", d / "sync", {"frame_0000.exr", "frame_0001.exr", "trace.vcd"});
  check_same_stats(d / "tight", d / "sync", "stats.json", {"arch"});
  check_same_files(d / "tight", d / "sync", {"frame_0000.exr", "frame_0001.exr", "trace.vcd"});
  // Every unit did work, so the waveform has something to agree on.
  CHECK(fs::file_size(d / "sync" / "trace.vcd") > 100000);
}
}  // namespace

TEST_CASE("cli: units running ahead report exactly what units waiting out every ray report", "[cli][ahead]") {
  check_running_ahead_is_exact("ideal", R"({"format": "oprt-arch/1", "ius": 12})", "");
}

TEST_CASE("cli: running ahead is exact with a BVH, memory latency and GPP costs too", "[cli][ahead]") {
  check_running_ahead_is_exact(
      "bvh",
      R"({"format": "oprt-arch/1", "ius": 6, "accel": "bvh", "memory": {"model": "latency", "latency_cycles": 20},
          "gpp": {"cycles_per_ray": 3, "cycles_per_hit": 40}})",
      "");
}

TEST_CASE("cli: running ahead is exact with a tree over each unit's spheres and caches on private DRAM channels",
          "[cli][ahead][top][cache]") {
  // A cache whose misses contend with no other unit's (one channel per unit) is something
  // only its own unit observes: units still run ahead, and must report what waiting does.
  check_running_ahead_is_exact(
      "cache",
      R"({"format": "oprt-arch/1", "ius": 6, "accel": "bvh", "top": "bvh", "balance": "sa_n", "subdivide": 2,
          "memory": {"model": "latency", "sram_bytes": 8192, "dram": {"units_per_channel": 1}}})",
      "");
}

TEST_CASE("cli: running ahead is exact at lt", "[cli][ahead]") {
  check_running_ahead_is_exact("lt", R"({"format": "oprt-arch/1", "ius": 9, "balance": "round_robin"})",
                               "--level lt --quantum 100ns");
}
