// The oprt command as a user runs it: exit codes and messages for bad input, and the
// timing levels compared run against run (two simulations need two processes).
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using namespace oprt::test;

TEST_CASE("cli: bad input ends with one message naming the place and exit status 2", "[cli]") {
  const fs::path d = temp_dir("bad");
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "ius": 0})";
  Result r = run_oprt("render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() + " --out " +
                  (d / "out").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("arch.json: /ius: value 0 is out of range") != std::string::npos);
  CHECK_FALSE(fs::exists(d / "out" / "stats.json"));

  r = run_oprt("render /nonexistent.json");
  CHECK(r.status == 2);
  CHECK(r.output.find("/nonexistent.json") != std::string::npos);

  r = run_oprt("render " + scene("paper_room.json") + " --frames 70:80");
  CHECK(r.status == 2);
  CHECK(r.output.find("frames 0:59 only") != std::string::npos);

  r = run_oprt("render " + scene("paper_room.json") + " --ius 0");
  CHECK(r.status == 2);

  r = run_oprt("render " + scene("paper_room.json") + " --quantum 5parsec --level lt");
  CHECK(r.status == 2);
  CHECK(r.output.find("unknown time unit") != std::string::npos);

  r = run_oprt("info " + scene("paper_room.json") + " --bogus");
  CHECK(r.status == 2);
}

TEST_CASE("cli: lt and at give identical images and busy cycles at every quantum", "[cli][lt]") {
  // Contended: FIFO depth 4, shared bus, memory latency; under each lt arbitration (bus.h).
  for (const std::string config : {"ideal", "sync", "calendar", "busy_until"}) {
    INFO(config);
    const fs::path d = temp_dir("levels_" + config);
    std::string arch = R"({"format": "oprt-arch/1", "ius": 6)";
    if (config != "ideal")
      arch += R"(, "ray_fifo_depth": 4, "bus": {"model": "shared", "bytes_per_cycle": 8, "lt_arbitration": ")" +
              config + R"("}, "memory": {"model": "latency", "latency_cycles": 10})";
    std::ofstream(d / "arch.json") << arch << "}";
    const std::string common = "render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() +
                               " --frames 5:6 --resolution 24x24 --no-progress";
    REQUIRE(run_oprt(common + " --level at --out " + (d / "at").string()).status == 0);
    const auto a = stats(d / "at");
    for (const char* quantum : {"10ns", "1us", "100us"}) {
      INFO("quantum " << quantum);
      const fs::path lt = d / (std::string("lt_") + quantum);
      REQUIRE(run_oprt(common + " --level lt --quantum " + quantum + " --out " + lt.string()).status == 0);
      for (const char* f : {"frame_0005.exr", "frame_0006.exr"})
        CHECK(oprt::read_exr((d / "at" / f).string()) == oprt::read_exr((lt / f).string()));
      const auto b = stats(lt);
      for (int f = 0; f < 2; ++f) {
        CHECK(a["frames"][f]["rays"] == b["frames"][f]["rays"]);
        for (int u = 0; u < 6; ++u) {
          const auto& ua = a["frames"][f]["ius"][u]["cycles"];
          const auto& ub = b["frames"][f]["ius"][u]["cycles"];
          CHECK(ua["sphere"] == ub["sphere"]);
          CHECK(ua["transform"] == ub["transform"]);
          CHECK(ua["primitive"] == ub["primitive"]);
          // Under the ideal architecture the units interact only through the GPP, which
          // handles an answer only when simulated time reaches it (gpp.cpp): it sees
          // answers in time order, so the decoupled run is the same schedule.
          if (config == "ideal") CHECK(ua == ub);
        }
        const double ma = a["frames"][f]["makespan_cycles"], mb = b["frames"][f]["makespan_cycles"];
        if (config == "ideal") CHECK(ma == mb);
        // Synchronising before every bus transfer makes requests reach the bus in time order,
        // as at `at`; only the order of simultaneous requests may differ (a few cycles here).
        if (config == "sync") CHECK(std::abs(ma - mb) <= 1e-3 * ma);
      }
    }
  }
}

TEST_CASE("cli: analytic equals at exactly under the ideal architecture", "[cli][analytic]") {
  const fs::path d = temp_dir("analytic");
  for (const char* scene_name : {"paper_room.json", "paper_polygons.json"}) {
    INFO(scene_name);
    const std::string common = "render " + scene(scene_name) + " --frames 7 --resolution 28x28 --ius 9 --no-progress";
    REQUIRE(run_oprt(common + " --level at --out " + (d / "at").string()).status == 0);
    REQUIRE(run_oprt(common + " --level analytic --out " + (d / "an").string()).status == 0);
    CHECK(oprt::read_exr((d / "at" / "frame_0007.exr").string()) == oprt::read_exr((d / "an" / "frame_0007.exr").string()));
    const auto a = stats(d / "at")["frames"][0], b = stats(d / "an")["frames"][0];
    CHECK(a["makespan_cycles"] == b["makespan_cycles"]);
    CHECK(a["rays"] == b["rays"]);
    for (int u = 0; u < 9; ++u) CHECK(a["ius"][u]["cycles"] == b["ius"][u]["cycles"]);  // idle and stall too
  }
  // And it refuses to trace: there are no simulated signals.
  const Result r = run_oprt("render " + scene("paper_room.json") + " --level analytic --vcd " + (d / "t.vcd").string());
  CHECK(r.status == 2);
}

TEST_CASE("cli: render --kernel watertight equals reference --kernel watertight - cycles are work x its costs",
          "[cli][watertight]") {
  const fs::path d = temp_dir("watertight");
  const std::string frame = " --frames 0 --resolution 24x24";
  REQUIRE(run_oprt("reference " + scene("paper_polygons.json") + frame + " --kernel watertight --out " +
                   (d / "ref").string()).status == 0);
  // at with the default costs; analytic with costs from an architecture file, and object
  // memory with a latency (so that bytes are streamed and counted).
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "kernel": "watertight",
      "costs": {"transform": 99, "triangle": [99, 99, 99, 99], "watertight": {"transform": 7, "triangle": [2, 3, 5, 11]}},
      "memory": {"model": "latency", "latency_cycles": 10, "bytes_per_cycle": 16}})";
  const std::string render = "render " + scene("paper_polygons.json") + frame + " --ius 5 --no-progress";
  REQUIRE(run_oprt(render + " --kernel watertight --level at --out " + (d / "at").string()).status == 0);
  REQUIRE(run_oprt(render + " --arch " + (d / "arch.json").string() + " --level analytic --out " +
                   (d / "an").string()).status == 0);
  REQUIRE(run_oprt(render + " --kernel watertight --level lt --quantum 10us --out " + (d / "lt").string()).status == 0);
  const auto ref = oprt::read_exr((d / "ref" / "frame_0000.exr").string());
  CHECK(oprt::read_exr((d / "at" / "frame_0000.exr").string()) == ref);
  CHECK(oprt::read_exr((d / "lt" / "frame_0000.exr").string()) == ref);
  CHECK(oprt::read_exr((d / "an" / "frame_0000.exr").string()) == ref);
  for (int u = 0; u < 5; ++u)
    for (const char* c : {"sphere", "transform", "primitive"})
      CHECK(stats(d / "at")["frames"][0]["ius"][u]["cycles"][c] == stats(d / "lt")["frames"][0]["ius"][u]["cycles"][c]);
  std::ifstream in(d / "ref" / "reference.json");
  const auto refj = nlohmann::json::parse(in);
  CHECK(refj["kernel"] == "watertight");
  CHECK(refj["triangle_exit_stages"] == nlohmann::json::array({"uv", "w", "det", "t"}));
  // The reference's counters are written by the render's code: the same keys, node tests
  // included (none: the reference has no tree over its spheres).
  const auto at_stats = stats(d / "at");
  for (const char* kind : {"primary", "shadow"}) {
    const auto& w = refj["frames"][0]["work"][kind];
    CHECK(w["node_tests"] == 0);
    for (const auto& [key, value] : at_stats["frames"][0]["ius"][0]["work"][kind].items()) CHECK(w.contains(key));
  }
  struct Costs {
    std::uint64_t transform, stage[4];
  };
  for (const auto& [dir, c] : {std::pair<const char*, Costs>{"at", {20, {18, 20, 21, 27}}},
                               std::pair<const char*, Costs>{"an", {7, {2, 3, 5, 11}}}}) {
    INFO(dir);
    const auto st = stats(d / dir);
    CHECK(st["arch"]["kernel"] == "watertight");
    std::uint64_t primary_tests = 0;
    for (const auto& u : st["frames"][0]["ius"]) {
      std::uint64_t transforms = 0, primitive = 0, spheres = 0, tests = 0;
      for (const char* kind : {"primary", "shadow"}) {
        const auto& w = u["work"][kind];
        transforms += w["transforms"].get<std::uint64_t>();
        spheres += w["sphere_tests"].get<std::uint64_t>();
        tests += w["triangle_tests"].get<std::uint64_t>();
        for (int k = 0; k < 4; ++k) primitive += c.stage[k] * w["triangle_exit_stage"][k].get<std::uint64_t>();
      }
      primary_tests += u["work"]["primary"]["triangle_tests"].get<std::uint64_t>();
      CHECK(u["cycles"]["sphere"].get<std::uint64_t>() == 9 * spheres);
      CHECK(u["cycles"]["transform"].get<std::uint64_t>() == c.transform * transforms);
      CHECK(u["cycles"]["primitive"].get<std::uint64_t>() == primitive);
      if (std::string(dir) == "an") CHECK(u["memory_bytes_read"].get<std::uint64_t>() == 36 * tests);  // v0, v1, v2
    }
    CHECK(primary_tests == refj["frames"][0]["work"]["primary"]["triangle_tests"].get<std::uint64_t>());
  }
}

TEST_CASE("cli: stats name the fields scripts rely on", "[cli]") {
  const fs::path d = temp_dir("stats");
  REQUIRE(run_oprt("render " + scene("paper_polygons.json") + " --frames 0 --resolution 16x16 --ius 4 --out " +
               d.string()).status == 0);
  const auto s = stats(d);
  const auto& f = s["frames"][0];
  for (const char* k : {"frame", "makespan_cycles", "parallel_efficiency", "wall_s", "rays", "ius"}) CHECK(f.contains(k));
  CHECK(f["rays"]["primary"] == 256);
  CHECK(f["ius"].size() == 4);
  for (const char* k : {"id", "spheres", "primitives", "rays", "cycles"}) CHECK(f["ius"][0].contains(k));
  for (const char* k : {"sphere", "transform", "primitive", "idle", "stall"}) CHECK(f["ius"][0]["cycles"].contains(k));
  // Parallel efficiency by its definition.
  double busy = 0;
  for (const auto& u : f["ius"]) busy += u["busy_cycles"].get<double>();
  CHECK(f["parallel_efficiency"].get<double>() == Approx(busy / (4 * f["makespan_cycles"].get<double>())));
  std::ifstream csv(d / "stats.csv");
  std::string header, row;
  std::getline(csv, header);
  int rows = 0;
  while (std::getline(csv, row)) ++rows;
  CHECK(header.rfind("frame,iu,", 0) == 0);
  CHECK(rows == 4);
  CHECK(fs::exists(d / "frame_0000.exr"));
  CHECK(fs::exists(d / "frame_0000.png"));
}

TEST_CASE("cli: --split chooses how objects become spheres and info shows local and world radii", "[cli][split]") {
  const std::string aff = std::string(OPRT_SOURCE_DIR) + "/tests/data/aff/features.aff";
  Result r = run_oprt("info " + aff);
  CHECK(r.status == 0);
  CHECK(r.output.find("(split extent, subdivide 1)") != std::string::npos);  // the default for .aff
  CHECK(r.output.find("r (local)  r (world)") != std::string::npos);
  r = run_oprt("info " + aff + " --split count");
  CHECK(r.output.find("spheres     5 (split count, subdivide 1)") != std::string::npos);  // one per object
  r = run_oprt("info " + scene("paper_room.json"));
  CHECK(r.output.find("spheres     32 (split count, subdivide 1)") != std::string::npos);  // the paper's, as written
  // render records the rule it used and each sphere's world radius.
  const fs::path d = temp_dir("split");
  const std::string render = "render " + aff + " --frames 0 --resolution 16x12 --ius 2 --level analytic --no-progress";
  REQUIRE(run_oprt(render + " --out " + (d / "extent").string()).status == 0);
  REQUIRE(run_oprt(render + " --split count --out " + (d / "count").string()).status == 0);
  const auto extent = stats(d / "extent"), count = stats(d / "count");
  CHECK(extent["arch"]["split"] == "extent");
  CHECK(count["arch"]["split"] == "count");
  CHECK(count["load_options"]["aff_max_object_triangles"] == 4096);
  CHECK(extent["load_options"]["aff_max_object_triangles"] == 0);
  CHECK(count["spheres"] == 5);
  CHECK(extent["spheres"].get<int>() > 5);
  CHECK(extent["sphere_list"][0].contains("world_radius"));
  // An unknown rule, on the command line or in an architecture file.
  r = run_oprt("info " + aff + " --split size");
  CHECK(r.status == 2);
  CHECK(r.output.find("--split") != std::string::npos);
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "split": "size"})";
  r = run_oprt(render + " --arch " + (d / "arch.json").string() + " --out " + (d / "bad").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("arch.json: /split") != std::string::npos);
}

TEST_CASE("cli: with --accel bvh the levels agree and the image is the brute-force one", "[cli][bvh]") {
  const fs::path d = temp_dir("bvh");
  const std::string common = "render " + scene("paper_room.json") + " --frames 4 --resolution 24x24 --ius 6 --no-progress";
  REQUIRE(run_oprt(common + " --out " + (d / "brute").string()).status == 0);
  REQUIRE(run_oprt(common + " --accel bvh --level at --out " + (d / "at").string()).status == 0);
  REQUIRE(run_oprt(common + " --accel bvh --level analytic --out " + (d / "an").string()).status == 0);
  REQUIRE(run_oprt("reference " + scene("paper_room.json") + " --frames 4 --resolution 24x24 --accel bvh --out " +
                   (d / "ref").string()).status == 0);
  const auto brute = oprt::read_exr((d / "brute" / "frame_0004.exr").string());
  for (const char* run : {"at", "an", "ref"}) {
    INFO(run);
    CHECK(oprt::read_exr((d / run / "frame_0004.exr").string()) == brute);
  }
  // Ideal architecture: analytic equals at exactly, box cycles included; busy = sum of parts.
  const auto a = stats(d / "at")["frames"][0], b = stats(d / "an")["frames"][0];
  CHECK(a["makespan_cycles"] == b["makespan_cycles"]);
  for (int u = 0; u < 6; ++u) {
    CHECK(a["ius"][u]["cycles"] == b["ius"][u]["cycles"]);
    const auto& c = a["ius"][u]["cycles"];
    CHECK(c["box"].get<std::uint64_t>() > 0);
    CHECK(a["ius"][u]["busy_cycles"] == c["sphere"].get<std::uint64_t>() + c["transform"].get<std::uint64_t>() +
                                            c["box"].get<std::uint64_t>() + c["primitive"].get<std::uint64_t>());
  }
  CHECK(stats(d / "at")["arch"]["accel"] == "bvh");
  CHECK(stats(d / "brute")["frames"][0]["ius"][0]["cycles"]["box"] == 0);
  // Contended: lt's busy cycles, box included, are at's.
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "ius": 6, "accel": "bvh", "ray_fifo_depth": 4,
      "bus": {"model": "shared", "bytes_per_cycle": 8}, "memory": {"model": "latency", "latency_cycles": 10}})";
  const std::string contended = "render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() +
                                " --frames 4 --resolution 24x24 --no-progress";
  REQUIRE(run_oprt(contended + " --level at --out " + (d / "cat").string()).status == 0);
  REQUIRE(run_oprt(contended + " --level lt --quantum 10us --out " + (d / "clt").string()).status == 0);
  CHECK(oprt::read_exr((d / "cat" / "frame_0004.exr").string()) == brute);
  CHECK(oprt::read_exr((d / "clt" / "frame_0004.exr").string()) == brute);
  const auto ca = stats(d / "cat")["frames"][0], cl = stats(d / "clt")["frames"][0];
  for (int u = 0; u < 6; ++u)
    for (const char* k : {"sphere", "transform", "box", "primitive"})
      CHECK(ca["ius"][u]["cycles"][k] == cl["ius"][u]["cycles"][k]);
}

TEST_CASE("cli: re-assignment moves geometry over the bus and reports its cycles", "[cli][balance]") {
  // feedback re-balances every frame after the first; what a unit gains is written into its
  // object memory, one transfer per unit whose spheres changed. On a shared bus of 8 bytes
  // per cycle with 1 arbitration cycle that transfer takes 1 + ceil(bytes / 8) cycles; on
  // the ideal bus no time at all. Derived here from each frame's per-unit sphere lists.
  const fs::path d = temp_dir("reassign");
  std::ofstream(d / "shared.json") << R"({"format": "oprt-arch/1", "ius": 8, "balance": "feedback", "subdivide": 4,
                                         "bus": {"model": "shared", "bytes_per_cycle": 8, "arbitration_cycles": 1}})";
  std::ofstream(d / "ideal.json") << R"({"format": "oprt-arch/1", "ius": 8, "balance": "feedback", "subdivide": 4})";
  const std::string common = "render " + scene("paper_room.json") + " --frames 0:2 --resolution 20x20 --no-progress";
  for (const char* run : {"shared_at", "shared_analytic", "ideal_at"}) {
    INFO(run);
    const std::string name(run);
    const std::string arch = (d / (name.rfind("shared", 0) == 0 ? "shared.json" : "ideal.json")).string();
    const std::string level = name.find("analytic") != std::string::npos ? "analytic" : "at";
    REQUIRE(run_oprt(common + " --arch " + arch + " --level " + level + " --out " + (d / run).string()).status == 0);
    const auto s = stats(d / run);
    const auto& spheres = s["sphere_list"];
    std::uint64_t moved_total = 0;
    for (std::size_t f = 0; f < 3; ++f) {
      const auto& fr = s["frames"][f];
      std::vector<int> seen(spheres.size(), 0);  // every frame's assignment is a partition
      std::uint64_t bytes = 0, cycles = 0;
      for (std::size_t u = 0; u < fr["ius"].size(); ++u) {
        const auto now = fr["ius"][u]["spheres"].get<std::vector<std::uint32_t>>();
        for (std::uint32_t x : now) ++seen.at(x);
        if (f == 0) continue;  // the set-up command loaded frame 0's geometry, outside the frame
        const auto before = s["frames"][f - 1]["ius"][u]["spheres"].get<std::vector<std::uint32_t>>();
        if (now == before) continue;
        std::uint64_t gained = 0;
        for (std::uint32_t x : now)
          if (std::find(before.begin(), before.end(), x) == before.end())
            gained += spheres[x]["primitives"].get<std::uint64_t>() * 48;  // a float triangle: 48 bytes
        bytes += gained;
        cycles += 1 + (gained + 7) / 8;
      }
      CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
      CHECK(fr["memory_load_bytes"].get<std::uint64_t>() == bytes);
      CHECK(fr["memory_load_cycles"].get<std::uint64_t>() == (name == "ideal_at" ? 0 : cycles));
      moved_total += bytes;
    }
    CHECK(moved_total > 0);  // the case does exercise a move
    CHECK(s["summary"]["memory_load_bytes_total"].get<std::uint64_t>() == moved_total);
  }
  // Whatever the policy moves, the image is the one of the paper's fixed assignment.
  REQUIRE(run_oprt(common + " --ius 8 --level analytic --out " + (d / "paper").string()).status == 0);
  for (const char* f : {"frame_0000.exr", "frame_0001.exr", "frame_0002.exr"})
    for (const char* run : {"shared_at", "shared_analytic", "ideal_at"})
      CHECK(oprt::read_exr((d / run / f).string()) == oprt::read_exr((d / "paper" / f).string()));
}

TEST_CASE("cli: compare prints the image difference as JSON, bad input exits 2", "[cli][compare]") {
  const fs::path d = temp_dir("compare");
  const std::string common = "reference " + scene("paper_polygons.json") + " --frames 0 --precision ";
  REQUIRE(run_oprt(common + "float --resolution 16x16 --out " + (d / "f").string()).status == 0);
  REQUIRE(run_oprt(common + "double --resolution 16x16 --out " + (d / "d").string()).status == 0);
  REQUIRE(run_oprt(common + "double --resolution 16x8 --out " + (d / "small").string()).status == 0);
  const std::string f = (d / "f" / "frame_0000.exr").string(), dbl = (d / "d" / "frame_0000.exr").string();

  Result r = run_oprt("compare " + dbl + " " + dbl);
  REQUIRE(r.status == 0);
  auto j = nlohmann::json::parse(r.output);
  CHECK(j["pixels"] == 256);
  CHECK(j["id_mismatches"] == 0);
  CHECK(j["color_rmse"] == 0.0);
  CHECK(j["max_rel_z"] == 0.0);
  // Every pixel with a finite Z is compared: the hits of the frame.
  const oprt::FrameImage img = oprt::read_exr(dbl);
  std::size_t hits = 0;
  for (float z : img.z) hits += std::isfinite(z);
  CHECK(j["z_compared"] == hits);

  r = run_oprt("compare " + f + " " + dbl);  // float against double: small but real differences
  REQUIRE(r.status == 0);
  j = nlohmann::json::parse(r.output);
  CHECK(j["reference"] == dbl);
  CHECK(j["max_rel_z"].get<double>() > 0);
  CHECK(j["max_rel_z"].get<double>() < 1e-3);

  r = run_oprt("compare " + f + " " + (d / "small" / "frame_0000.exr").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("sizes differ: 16x16 against 16x8") != std::string::npos);
  r = run_oprt("compare " + f + " " + (d / "nothing.exr").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("nothing.exr") != std::string::npos);
}

namespace {
// oprt started in the background with stdout on a pipe (read line by line) and stderr in a file.
struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
  fs::path err;
};

Child start_oprt(const std::vector<std::string>& args, const fs::path& err) {
  int fds[2];
  REQUIRE(pipe(fds) == 0);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    dup2(fds[1], 1);
    if (!std::freopen(err.c_str(), "w", stderr)) _exit(127);
    close(fds[0]);
    std::vector<char*> argv;
    std::string bin = OPRT_BINARY;
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(bin.c_str(), argv.data());
    _exit(127);
  }
  close(fds[1]);
  return {pid, fdopen(fds[0], "r"), err};
}

// Reads stdout until `lines` lines starting with "frame" have appeared.
void await_frames(Child& c, int lines) {
  char buf[512];
  int seen = 0;
  while (seen < lines && std::fgets(buf, sizeof buf, c.out))
    if (std::string(buf).rfind("frame", 0) == 0) ++seen;
  REQUIRE(seen == lines);
}

int finish(Child& c) {
  char buf[512];
  while (std::fgets(buf, sizeof buf, c.out)) {
  }
  std::fclose(c.out);
  int st = 0;
  waitpid(c.pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// What an interrupted run must leave in `out`: every frame file whole and readable, the
// statistics listing exactly those frames, no temporary files, and nothing else.
std::vector<int> check_outputs(const fs::path& out, int width, int height, const char* stats_file) {
  std::vector<int> frames;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    CHECK(name[0] != '.');  // no temporary (.NAME.tmpPID) left behind
    if (name.rfind("frame_", 0) == 0 && e.path().extension() == ".exr") {
      frames.push_back(std::stoi(name.substr(6, 4)));
      const oprt::FrameImage img = oprt::read_exr(e.path().string());  // throws if truncated
      CHECK(img.width == width);
      CHECK(img.height == height);
      CHECK(fs::exists(out / (name.substr(0, 10) + ".png")));
    }
  }
  std::sort(frames.begin(), frames.end());
  std::vector<int> listed;
  std::ifstream in(out / stats_file);
  const auto doc = nlohmann::json::parse(in);
  for (const auto& f : doc["frames"]) listed.push_back(f["frame"].get<int>());
  CHECK(listed == frames);
  return frames;
}
}  // namespace

TEST_CASE("cli: SIGINT or SIGTERM stops a render cleanly, saying which frames completed", "[cli][signal]") {
  for (int sig : {SIGINT, SIGTERM}) {
    const std::string name = sig == SIGINT ? "SIGINT" : "SIGTERM";
    INFO(name);
    const fs::path d = temp_dir("signal_" + name);
    Child c = start_oprt({"render", scene("paper_room.json"), "--frames", "0:59", "--resolution", "24x16", "--ius",
                          "4", "--no-progress", "--out", (d / "out").string(), "--vcd", (d / "out" / "t.vcd").string()},
                         d / "err.txt");
    await_frames(c, 2);
    kill(c.pid, sig);
    const int status = finish(c);
    CHECK(status == 128 + sig);
    const std::string err = slurp(d / "err.txt");
    CHECK_THAT(err, Catch::StartsWith("oprt: interrupted by " + name + ": frames 0:"));
    const std::vector<int> frames = check_outputs(d / "out", 24, 16, "stats.json");
    REQUIRE(frames.size() >= 2);
    REQUIRE(frames.size() < 60);
    const int n = static_cast<int>(frames.size());
    for (int i = 0; i < n; ++i) CHECK(frames[i] == i);
    CHECK_THAT(err, Catch::Contains("frames 0:" + std::to_string(n - 1) + " of 0:59 completed; frame " +
                                    std::to_string(n) + " abandoned"));
    // The trace covers the completed frames and ends at the last one's end.
    const std::string vcd = slurp(d / "out" / "t.vcd");
    CHECK(vcd.find("$enddefinitions") != std::string::npos);
    const auto last_hash = vcd.rfind("\n#");
    REQUIRE(last_hash != std::string::npos);
    CHECK(vcd.find('\n', last_hash + 1) == vcd.size() - 1);  // the final line is the end time
    CHECK(fs::exists(d / "out" / "t.gtkw"));
  }
}

TEST_CASE("cli: SIGINT stops the reference renderer cleanly too", "[cli][signal]") {
  const fs::path d = temp_dir("signal_reference");
  Child c = start_oprt({"reference", scene("paper_polygons.json"), "--frames", "0:59", "--resolution", "32x24",
                        "--out", (d / "out").string()},
                       d / "err.txt");
  await_frames(c, 1);
  kill(c.pid, SIGINT);
  CHECK(finish(c) == 130);
  CHECK_THAT(slurp(d / "err.txt"), Catch::StartsWith("oprt: interrupted by SIGINT: frame"));
  const std::vector<int> frames = check_outputs(d / "out", 32, 24, "reference.json");
  CHECK(frames.size() >= 1);
}

TEST_CASE("cli: a render killed outright never leaves a truncated file under a final name", "[cli][signal]") {
  // SIGKILL cannot be handled: what makes this safe is that every file is written under a
  // temporary name and renamed when complete.
  const fs::path d = temp_dir("signal_kill");
  Child c = start_oprt({"render", scene("paper_room.json"), "--frames", "0:59", "--resolution", "32x32", "--ius", "4",
                        "--no-progress", "--out", (d / "out").string()},
                       d / "err.txt");
  await_frames(c, 2);
  kill(c.pid, SIGKILL);
  CHECK(finish(c) == 128 + SIGKILL);
  std::vector<int> frames;
  for (const auto& e : fs::directory_iterator(d / "out")) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.') {  // a temporary the kill interrupted: hidden, and named as one
      CHECK(name.find(".tmp") != std::string::npos);
      continue;
    }
    if (e.path().extension() == ".exr") {
      frames.push_back(std::stoi(name.substr(6, 4)));
      CHECK(oprt::read_exr(e.path().string()).width == 32);
    }
  }
  CHECK(frames.size() >= 2);
  // The statistics are written when a run ends or is stopped: a killed run has none under
  // their final names (docs/reliability.md), only its hidden spool.
  CHECK_FALSE(fs::exists(d / "out" / "stats.json"));
  CHECK_FALSE(fs::exists(d / "out" / "stats.csv"));
}

TEST_CASE("cli: a tolerated BART quirk warns on stderr, a bad glTF uri exits 2 with a short message",
          "[cli][issue15]") {
  const fs::path d = temp_dir("quirks");
  // A rotation list that starts again, as BART's robots write one: it loads, with a warning.
  std::ofstream(d / "gun.aff") << "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 0.1 resolution 8 8\n"
                                  "a 0 4 5\nl 0 0 5\nf 1 1 1 1 0 1 0 1\n"
                                  "x gun\n{\np 3\n0 0 0\n1 0 0\n0 1 0\n}\n"
                                  "k gun\n{\nrot 6\n0 0 0 1 0 0 0 0\n1 0 0 1 90 0 0 0\n2 0 0 1 180 0 0 0\n"
                                  "1 0 0 1 90 0 0 0\n2 0 0 1 180 0 0 0\n3 0 0 1 270 0 0 0\n}\n";
  Result r = run_oprt("info " + (d / "gun.aff").string());
  CHECK(r.status == 0);
  CHECK(r.output.find("oprt: warning: " + (d / "gun.aff").string() + ": line 14: 'rot' keys of 'k gun': times go "
                      "backwards: key 4 of 6 (line 18) at time 1 after 2") != std::string::npos);

  // A buffer uri of 5,000 characters: the loader's own error at /buffers/0/uri, not a 19 KB
  // std::filesystem message with exit status 1.
  std::ifstream in(std::string(OPRT_SOURCE_DIR) + "/tests/data/gltf/animated.gltf");
  nlohmann::json doc = nlohmann::json::parse(in);
  doc["buffers"][0]["uri"] = std::string(5000, 'a');
  std::ofstream(d / "long.gltf") << doc.dump();
  r = run_oprt("info " + (d / "long.gltf").string());
  CHECK(r.status == 2);
  CHECK(r.output.find((d / "long.gltf").string() + ": /buffers/0/uri: neither a data URI nor a usable file name") !=
        std::string::npos);
  CHECK(r.output.size() < 500);
}

TEST_CASE("cli: info lists the reflective and transmissive materials and the vertex normals, a bad ior exits 2",
          "[cli][issue29][info]") {
  const fs::path d = temp_dir("whitted");
  // f: Ks 0.3 reflects, T 0.5 with index 1.5 transmits; a pp patch carries normals, a p does not.
  std::ofstream(d / "glass.aff") << "v from 0 0 5 at 0 0 0 up 0 1 0 angle 45 hither 0.1 resolution 8 8\n"
                                    "l 0 0 5\nf 1 1 1 0.5 0.3 10 0.5 1.5\n"
                                    "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n"
                                    "fm 0 0 0 0.5 0.5 0.5 0 0 0 1 0 0\np 3\n0 0 1\n1 0 1\n0 1 1\n";
  Result r = run_oprt("info " + (d / "glass.aff").string());
  CHECK(r.status == 0);
  CHECK(r.output.find("normals     1 of 2 triangles carry vertex normals (interpolated for shading)") !=
        std::string::npos);
  CHECK(r.output.find("materials   2 used, 1 reflective, 1 transmissive (reflection and refraction rays to depth 5, "
                      "the scene's bound)") != std::string::npos);
  CHECK(r.output.find("not yet traced") == std::string::npos);
  CHECK(r.output.find("(   0.3,    0.3,    0.3) (   0.5,    0.5,    0.5)      1.5") != std::string::npos);

  const std::string head = R"({"format": "oprt-scene/1", "camera": {"eye": [0, 0, 5], "target": [0, 0, 0]},)";
  const std::string tri = R"("objects": [{"material": "m", "mesh": {"vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,2]]}}]})";
  std::ofstream(d / "bad.json") << head + R"( "materials": {"m": {"ior": 0.5}}, )" + tri;
  r = run_oprt("info " + (d / "bad.json").string());
  CHECK(r.status == 2);
  CHECK(r.output.find((d / "bad.json").string() + ": /materials/m/ior: value 0.5 is out of range [1, 10]") !=
        std::string::npos);
}

TEST_CASE("cli: a ray FIFO never holds more rays than its depth, at every level", "[cli][fifo]") {
  // Four units behind FIFOs of depth 2, the GPP free to write a ray every cycle: units take
  // tens of cycles per ray, so every FIFO fills to its depth and the GPP then waits for room.
  // No FIFO may ever hold a third ray, and each reaches 2; every ray written is read.
  const fs::path d = temp_dir("fifo_depth");
  std::ofstream(d / "arch.json") << R"({"format": "oprt-arch/1", "ius": 4, "ray_fifo_depth": 2})";
  for (const char* level : {"at", "lt", "analytic"}) {
    INFO(level);
    const fs::path out = d / level;
    const Result r = run_oprt("render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() +
                              " --level " + level + " --frames 0 --resolution 16x16 --no-progress --out " + out.string());
    REQUIRE(r.status == 0);
    const auto s = stats(out);
    std::uint64_t most = 0;
    for (const auto& u : s["frames"][0]["ius"]) {
      CHECK(u["fifo"]["peak"].get<std::uint64_t>() <= 2);
      CHECK(u["fifo"]["pushes"] == u["fifo"]["pops"]);
      most = std::max(most, u["fifo"]["peak"].get<std::uint64_t>());
    }
    CHECK(most == 2);
  }
}
