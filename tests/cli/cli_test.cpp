// The oprt command as a user runs it: exit codes and messages for bad input, and the
// timing levels compared run against run (two simulations need two processes).
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

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

TEST_CASE("cli: lt and at give identical images and busy cycles", "[cli][lt]") {
  for (const char* config : {"ideal", "contended"}) {
    INFO(config);
    const fs::path d = temp_dir(std::string("levels_") + config);
    std::string arch = R"({"format": "oprt-arch/1", "ius": 6)";
    if (std::string(config) == "contended")
      arch += R"(, "ray_fifo_depth": 4, "bus": {"model": "shared", "bytes_per_cycle": 8},
                "memory": {"model": "latency", "latency_cycles": 10})";
    std::ofstream(d / "arch.json") << arch << "}";
    const std::string common = "render " + scene("paper_room.json") + " --arch " + (d / "arch.json").string() +
                               " --frames 5:6 --resolution 24x24 --no-progress";
    REQUIRE(run_oprt(common + " --level at --out " + (d / "at").string()).status == 0);
    REQUIRE(run_oprt(common + " --level lt --quantum 10us --out " + (d / "lt").string()).status == 0);
    for (const char* f : {"frame_0005.exr", "frame_0006.exr"})
      CHECK(oprt::read_exr((d / "at" / f).string()) == oprt::read_exr((d / "lt" / f).string()));
    const auto a = stats(d / "at"), b = stats(d / "lt");
    for (int f = 0; f < 2; ++f)
      for (int u = 0; u < 6; ++u) {
        const auto& ua = a["frames"][f]["ius"][u]["cycles"];
        const auto& ub = b["frames"][f]["ius"][u]["cycles"];
        CHECK(ua["sphere"] == ub["sphere"]);
        CHECK(ua["transform"] == ub["transform"]);
        CHECK(ua["primitive"] == ub["primitive"]);
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
  std::ifstream in(d / "out" / "stats.json");
  const auto stats = nlohmann::json::parse(in);  // whole: it parses
  CHECK(stats["frames"].size() >= 2);
  CHECK(frames.size() >= stats["frames"].size());  // stats are written after a frame's images
}
