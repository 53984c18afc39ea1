// `--top bvh` (a tree over each unit's spheres) and `--sram` (object memory with a capacity,
// a cache in front of DRAM when a unit's spheres do not fit), as a user runs them: the image
// is always the flat, unlimited one; the figures that must follow are derived here from the
// run's own per-unit sphere lists and counts.
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <map>

using namespace oprt::test;

namespace {
std::uint64_t u64(const nlohmann::json& j) { return j.get<std::uint64_t>(); }

void check_same_images(const fs::path& a, const fs::path& b, const std::vector<std::string>& frames) {
  for (const std::string& f : frames) {
    INFO(a.string() << " against " << b.string() << ": " << f);
    CHECK(oprt::read_exr((a / f).string()) == oprt::read_exr((b / f).string()));
  }
}
}  // namespace

TEST_CASE("cli: --top bvh renders the flat image at every level, charging node tests and the GPP's refit",
          "[cli][top]") {
  const fs::path d = temp_dir("top");
  const std::string common = "render " + scene("paper_room.json") +
                             " --frames 3:4 --resolution 24x24 --ius 8 --balance sa_n --subdivide 4 --no-progress";
  REQUIRE(run_oprt(common + " --out " + (d / "flat").string()).status == 0);
  for (const char* level : {"at", "lt", "analytic"})
    REQUIRE(run_oprt(common + " --top bvh --level " + level + " --out " + (d / level).string()).status == 0);
  for (const char* level : {"at", "lt", "analytic"}) check_same_images(d / level, d / "flat", {"frame_0003.exr", "frame_0004.exr"});

  const auto flat = stats(d / "flat"), at = stats(d / "at"), an = stats(d / "analytic");
  CHECK(at["arch"]["top"] == "bvh");
  for (std::size_t f = 0; f < 2; ++f) {
    INFO("frame " << f);
    const auto& a = at["frames"][f];
    const auto& b = an["frames"][f];
    const auto& fl = flat["frames"][f];
    CHECK(a["makespan_cycles"] == b["makespan_cycles"]);  // ideal architecture: analytic is exact
    // A tree over n spheres has 2n - 1 nodes; the GPP refits every node every frame, at
    // gpp.cycles_per_node (20 by default); it builds them only for the first frame.
    std::uint64_t nodes = 0, node_cycles = 0, node_tests = 0, sphere_tests = 0, flat_sphere_tests = 0;
    for (std::size_t u = 0; u < a["ius"].size(); ++u) {
      const auto& iu = a["ius"][u];
      nodes += 2 * iu["spheres"].size() - 1;
      CHECK(iu["cycles"] == b["ius"][u]["cycles"]);
      const auto& c = iu["cycles"];
      CHECK(u64(iu["busy_cycles"]) == u64(c["sphere"]) + u64(c["transform"]) + u64(c["box"]) + u64(c["primitive"]) +
                                          u64(c["node"]));
      const std::uint64_t tests = u64(iu["work"]["primary"]["node_tests"]) + u64(iu["work"]["shadow"]["node_tests"]);
      CHECK(u64(c["node"]) == 13 * tests);  // the node test's schedule: 13 cycles
      CHECK(tests >= u64(iu["rays"]));       // every ray tests the root at least
      node_cycles += u64(c["node"]);
      node_tests += tests;
      sphere_tests += u64(iu["work"]["primary"]["sphere_tests"]) + u64(iu["work"]["shadow"]["sphere_tests"]);
      flat_sphere_tests +=
          u64(fl["ius"][u]["work"]["primary"]["sphere_tests"]) + u64(fl["ius"][u]["work"]["shadow"]["sphere_tests"]);
      CHECK(fl["ius"][u]["cycles"]["node"] == 0);
    }
    CHECK(u64(a["gpp"]["refit_nodes"]) == nodes);
    CHECK(u64(a["gpp"]["refit_cycles"]) == 20 * nodes);
    CHECK(u64(a["gpp"]["nodes_built"]) == (f == 0 ? nodes : 0));
    CHECK(b["gpp"] == a["gpp"]);
    CHECK(u64(fl["gpp"]["refit_cycles"]) == 0);
    CHECK(node_cycles > 0);
    CHECK(sphere_tests * 4 < flat_sphere_tests);
    // Bus traffic: the configuration writes grow by a node's 32 bytes per node, every ray
    // (broadcast once) by its reciprocal direction's 12 bytes; the rest is the same.
    const std::uint64_t rays = u64(a["rays"]["primary"]) + u64(a["rays"]["shadow"]);
    CHECK(u64(a["bus"]["bytes"]) == u64(fl["bus"]["bytes"]) + 32 * nodes + 12 * rays);
  }
  CHECK(u64(at["summary"]["gpp_refit_cycles_total"]) ==
        u64(at["frames"][0]["gpp"]["refit_cycles"]) + u64(at["frames"][1]["gpp"]["refit_cycles"]));
  // The waveform shows the refit.
  REQUIRE(run_oprt(common + " --top bvh --vcd " + (d / "t.vcd").string() + " --out " + (d / "vcd").string()).status == 0);
  CHECK(bytes_of(d / "t.vcd").find(" refit $end") != std::string::npos);
}

TEST_CASE("cli: an object memory that holds every unit's spheres gives exactly the unlimited memory's figures",
          "[cli][cache]") {
  const fs::path d = temp_dir("sram_fits");
  // paper_room's largest sphere holds about 10k triangles (480 kB): 4 MB per unit holds any.
  for (const std::string extra : {"", " --accel bvh --top bvh"}) {
    std::ofstream(d / "lat.json") << R"({"format": "oprt-arch/1", "ius": 8, "memory": {"model": "latency"}})";
    const std::string common = "render " + scene("paper_room.json") + " --arch " + (d / "lat.json").string() +
                               " --frames 0:1 --resolution 24x24 --no-progress" + extra;
    REQUIRE(run_oprt(common + " --out " + (d / "unlimited").string()).status == 0);
    REQUIRE(run_oprt(common + " --sram 4M --out " + (d / "fits").string()).status == 0);
    nlohmann::json a = without_wall_clock(stats(d / "unlimited")), b = without_wall_clock(stats(d / "fits"));
    CHECK(b["arch"]["memory"]["sram_bytes"] == 4 << 20);
    a.erase("arch");
    b.erase("arch");
    CHECK(a == b);
    for (const auto& u : b["frames"][1]["ius"]) {
      CHECK(u["memory"]["cache"] == false);
      CHECK(u["memory"]["misses"] == 0);
      CHECK(u["memory"]["stall_cycles"] == u["cycles"]["stall"]);  // the on-chip memory's latency stall
    }
    check_same_images(d / "unlimited", d / "fits", {"frame_0000.exr", "frame_0001.exr"});
  }
}

TEST_CASE("cli: 16 KB per unit on paper_room: misses, a longer makespan, the same image", "[cli][cache]") {
  const fs::path d = temp_dir("sram_16k");
  const std::string common = "render " + scene("paper_room.json") + " --frames 0:1 --resolution 32x32 --no-progress";
  REQUIRE(run_oprt(common + " --out " + (d / "ideal").string()).status == 0);
  REQUIRE(run_oprt(common + " --sram 16K --vcd " + (d / "t.vcd").string() + " --out " + (d / "at").string()).status == 0);
  REQUIRE(run_oprt(common + " --sram 16K --level analytic --out " + (d / "an").string()).status == 0);
  for (const char* run : {"at", "an"}) check_same_images(d / run, d / "ideal", {"frame_0000.exr", "frame_0001.exr"});
  const auto ideal = stats(d / "ideal"), at = stats(d / "at");
  CHECK(at["arch"]["memory"]["sram_bytes"] == 16384);
  for (std::size_t f = 0; f < 2; ++f) {
    INFO("frame " << f);
    const auto& a = at["frames"][f];
    const auto& i = ideal["frames"][f];
    CHECK(u64(a["makespan_cycles"]) > u64(i["makespan_cycles"]));
    CHECK(a["busy_cycles"] == i["busy_cycles"]);  // the same work, only waiting for memory added
    std::uint64_t misses = 0, caches = 0;
    for (std::size_t u = 0; u < a["ius"].size(); ++u) {
      const auto& m = a["ius"][u]["memory"];
      // A unit is a cache exactly when its spheres need more than 16 KB: 48 bytes a triangle.
      CHECK(u64(m["assigned_bytes"]) == 48 * u64(a["ius"][u]["primitives"]));
      CHECK(m["cache"] == (u64(m["assigned_bytes"]) > 16384));
      CHECK(u64(m["dram_bytes"]) == 64 * u64(m["misses"]));  // 64-byte lines
      CHECK(u64(m["stall_cycles"]) == u64(a["ius"][u]["cycles"]["stall"]));  // an ideal bus adds none
      if (m["cache"] == false) CHECK(u64(m["hits"]) + u64(m["misses"]) == 0);
      misses += u64(m["misses"]);
      caches += m["cache"] == true;
    }
    CHECK(caches > 0);
    CHECK(misses > 0);
  }
  // The waveform counts each cache's misses in flight.
  CHECK(bytes_of(d / "t.vcd").find(" misses $end") != std::string::npos);
}

TEST_CASE("cli: with a DRAM channel per unit the analytic level times the caches exactly as at", "[cli][cache]") {
  const fs::path d = temp_dir("sram_private");
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "ius": 8, "accel": "bvh",
      "memory": {"model": "latency", "sram_bytes": 8192, "cache": {"ways": 2, "replacement": "fifo"},
                 "dram": {"units_per_channel": 1, "latency_cycles": 60}}})";
  const std::string common = "render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() +
                             " --frames 0:1 --resolution 24x24 --no-progress";
  REQUIRE(run_oprt(common + " --level at --out " + (d / "at").string()).status == 0);
  REQUIRE(run_oprt(common + " --level analytic --out " + (d / "an").string()).status == 0);
  nlohmann::json a = without_wall_clock(stats(d / "at")), b = without_wall_clock(stats(d / "an"));
  a.erase("arch");
  b.erase("arch");
  CHECK(a == b);
  std::uint64_t misses = 0;
  for (const auto& u : a["frames"][1]["ius"]) misses += u64(u["memory"]["misses"]);
  CHECK(misses > 0);
}

// Issue 32: memory.dram.path "external" sends the fills out of the engine's memory port; the
// oprt command binds its own DRAM model there, which must give exactly the figures of
// "channel" (the same channels, latency and rate), at every level, with a channel per unit
// or shared, under a contended bus and shallow FIFOs, serial and pipelined units alike.
TEST_CASE("cli: memory.dram.path external through oprt's own DRAM gives exactly channel's figures", "[cli][cache]") {
  const fs::path d = temp_dir("dram_external");
  for (const char* level : {"at", "lt", "analytic"})
    for (const char* iu : {"serial", "pipelined"})
      for (int per_channel : {1, 2}) {
        INFO(level << " " << iu << " units_per_channel " << per_channel);
        const auto arch = [&](const char* path) {
          const fs::path f = d / (std::string(path) + ".json");
          std::ofstream(f) << R"({"format": "oprt-arch/1", "ius": 8, "subdivide": 2, "balance": "sa_n", "ray_fifo_depth": 2,
              "bus": {"model": "shared", "bytes_per_cycle": 8, "arbitration_cycles": 1},
              "memory": {"sram_bytes": 4096, "cache": {"ways": 2, "misses_outstanding": 2},
                         "dram": {"path": ")" << path << R"(", "units_per_channel": )" << per_channel << "}}}";
          return f.string();
        };
        const std::string common = "render " + scene("paper_room.json") + " --frames 0 --resolution 16x16 --no-progress" +
                                   " --level " + level + " --iu " + iu;
        REQUIRE(run_oprt(common + " --arch " + arch("channel") + " --out " + (d / "channel").string()).status == 0);
        REQUIRE(run_oprt(common + " --arch " + arch("external") + " --out " + (d / "external").string()).status == 0);
        nlohmann::json a = without_wall_clock(stats(d / "channel")), b = without_wall_clock(stats(d / "external"));
        CHECK(b["arch"]["memory"]["dram"]["path"] == "external");
        a.erase("arch");
        b.erase("arch");
        CHECK(a == b);
        std::uint64_t misses = 0;
        for (const auto& u : a["frames"][0]["ius"]) misses += u64(u["memory"]["misses"]);
        CHECK(misses > 0);
      }
}

TEST_CASE("cli: a bad --sram ends with one message and exit status 2", "[cli][cache]") {
  Result r = run_oprt("render " + scene("paper_room.json") + " --sram lots");
  CHECK(r.status == 2);
  CHECK(r.output.find("--sram: lots: expected a byte count") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --sram 100");
  CHECK(r.status == 2);
  CHECK(r.output.find("smaller than one cache set") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --top octree");
  CHECK(r.status == 2);
}

TEST_CASE("cli: through 16 KB caches each unit's timeline slices add up to its busy and stall cycles",
          "[cli][cache][trace]") {
  const fs::path d = temp_dir("sram_timeline");
  const std::string common =
      "render " + scene("paper_room.json") + " --frames 0 --resolution 24x24 --sram 16K --no-progress";
  REQUIRE(run_oprt(common + " --timeline " + (d / "t.json").string() + " --out " + d.string()).status == 0);
  REQUIRE(run_oprt(common + " --vcd " + (d / "t.vcd").string() + " --trace-signals memory --out " + (d / "m").string())
              .status == 0);
  const auto st = stats(d);
  std::ifstream in(d / "t.json");
  const nlohmann::json timeline = nlohmann::json::parse(in);
  // Track names ("IU 3") by thread id, then every slice's duration (us, at 100 MHz: 100 cycles).
  std::map<std::uint64_t, int> unit_of;
  for (const auto& e : timeline["traceEvents"])
    if (e["ph"] == "M" && e["name"] == "thread_name" && e["args"]["name"].get<std::string>().rfind("IU ", 0) == 0)
      unit_of[e["tid"].get<std::uint64_t>()] = std::stoi(e["args"]["name"].get<std::string>().substr(3));
  std::map<int, double> cycles;
  for (const auto& e : timeline["traceEvents"])
    if (e["ph"] == "X" && unit_of.count(e["tid"].get<std::uint64_t>()))
      cycles[unit_of[e["tid"].get<std::uint64_t>()]] += e["dur"].get<double>() * 100;
  int caches = 0;
  for (const auto& u : st["frames"][0]["ius"]) {
    const int id = u["id"].get<int>();
    INFO("unit " << id);
    CHECK(cycles[id] == Approx(static_cast<double>(u64(u["busy_cycles"]) + u64(u["memory"]["stall_cycles"]))).margin(1));
    caches += u["memory"]["cache"] == true;
  }
  CHECK(caches > 0);
  // --trace-signals memory: the caches' misses in flight, nothing else.
  const std::string vcd = bytes_of(d / "t.vcd");
  CHECK(vcd.find(" misses $end") != std::string::npos);
  CHECK(vcd.find(" state $end") == std::string::npos);
  CHECK(vcd.find(" occupancy $end") == std::string::npos);
}
