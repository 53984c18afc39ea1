// The oprt command as a user runs it: exit codes and messages for bad input, and the
// timing levels compared run against run (two simulations need two processes).
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {
struct Result {
  int status;
  std::string output;  // stdout and stderr
};

Result run_oprt(const std::string& args) {
  const std::string cmd = std::string(OPRT_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

std::string scene(const std::string& name) { return std::string(OPRT_SOURCE_DIR) + "/scenes/" + name; }

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("oprt_cli_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

nlohmann::json stats(const fs::path& dir) {
  std::ifstream in(dir / "stats.json");
  return nlohmann::json::parse(in);
}
}  // namespace

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
