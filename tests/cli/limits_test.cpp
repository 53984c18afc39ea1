// Every input as users write it (issue 23): numbers at their limits, one past and far past;
// memory a run cannot have, refused before it is allocated; outputs that cannot be written,
// refused before anything is; simulated time and technology values that do not fit, refused
// naming the setting; long runs whose cost per frame does not grow. Each finding of the issue
// has its case here, named after it.
#include "cli_util.h"

#include <catch2/catch.hpp>

#include <cerrno>
#include <fcntl.h>
#include <fstream>
#include <regex>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

using namespace oprt::test;

namespace {

// ASan's shadow memory and quarantine make resident memory no measure of the program's own.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kMeasuresMemory = false;
#else
constexpr bool kMeasuresMemory = true;
#endif

struct Measured {
  int status;
  std::string output;
  long peak_kb;  // the process's maximum resident set
};

// Runs oprt with `args` (no shell), its output into `log`, and reports its peak memory.
Measured run_measured(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>(OPRT_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(OPRT_BINARY, argv.data());
    _exit(127);
  }
  int st = 0;
  rusage ru{};
  wait4(pid, &st, 0, &ru);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, bytes_of(log), ru.ru_maxrss};
}

Result render(const std::string& args) { return run_oprt("render " + scene("paper_room.json") + " " + args); }

void refused(const Result& r, const std::vector<std::string>& says) {
  INFO(r.output);
  CHECK(r.status == 2);
  for (const std::string& s : says) CHECK_THAT(r.output, Catch::Contains(s));
  CHECK_THAT(r.output, !Catch::Contains("E549"));
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);  // one message
}

std::string write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

// A scene of one generated mesh (and more objects if given), 8x8.
std::string generated(const fs::path& d, const std::string& name, const std::string& objects, int frames = 1) {
  return write(d / (name + ".json"),
               R"({"format": "oprt-scene/1", "camera": {"eye": [0, 3, 6], "target": [0, 0, 0], "up": [0, 1, 0]},
                   "image": {"width": 8, "height": 8}, "lights": [{"position": [3, 5, 4], "color": [1, 1, 1]}],
                   "objects": [)" + objects + R"(], "frames": )" + std::to_string(frames) + "}");
}

std::uint64_t estimate_in(const std::string& message) {
  std::smatch m;
  REQUIRE(std::regex_search(message, m, std::regex(R"(would need about [^(]*\((\d+) bytes\))")));
  return std::stoull(m[1]);
}

}  // namespace

TEST_CASE("limits: byte counts on the command line and in the architecture file, at and past 1 TiB", "[cli][limits]") {
  const fs::path d = temp_dir("limits_bytes");
  const std::string run = "--frames 0 --resolution 8x8 --no-progress --out " + (d / "o").string();
  for (const char* sram : {"1G", "1073741824", "1.5G", "1T"}) {
    INFO(sram);
    REQUIRE(render(run + " --sram " + sram).status == 0);
  }
  CHECK(stats(d / "o")["arch"]["memory"]["sram_bytes"] == 1099511627776ull);
  refused(render(run + " --sram 1099511627777"), {"--sram: 1099511627777: ", "at most 1 TiB (1099511627776 bytes)"});
  refused(render(run + " --sram 2T"), {"--sram: 2T: value 2T (2199023255552 bytes) is more than the limit: at most 1 TiB"});
  refused(render(run + " --sram 99999999999999999999999"), {"--sram", "at most 1 TiB"});
  refused(render(run + " --sram 64X"), {"--sram: 64X: expected a byte count such as 65536, 64K, 4M or 1.5G"});

  const std::string arch4g = write(d / "a4g.json", R"({"format": "oprt-arch/1", "memory": {"sram_bytes": 4294967296}})");
  REQUIRE(render(run + " --arch " + arch4g).status == 0);
  CHECK(stats(d / "o")["arch"]["memory"]["sram_bytes"] == 4294967296ull);
  const std::string arch1t = write(d / "a1t.json", R"({"format": "oprt-arch/1", "memory": {"sram_bytes": "1 TiB"}})");
  REQUIRE(render(run + " --arch " + arch1t).status == 0);
  const std::string past = write(d / "past.json", R"({"format": "oprt-arch/1", "memory": {"sram_bytes": 1099511627777}})");
  refused(render(run + " --arch " + past), {"past.json: /memory/sram_bytes: value 1099511627777", "at most 1 TiB"});
  const std::string far = write(d / "far.json", R"({"format": "oprt-arch/1", "memory": {"sram_bytes": "4096T"}})");
  refused(render(run + " --arch " + far), {"far.json: /memory/sram_bytes: value 4096T", "at most 1 TiB"});

  // --max-memory: the whole of 64 bits.
  REQUIRE(render(run + " --max-memory 18446744073709551615").status == 0);
  refused(render(run + " --max-memory 18446744073709551616"), {"--max-memory", "more than the limit"});
}

TEST_CASE("limits: counts and times on the command line, at and past their limits", "[cli][limits]") {
  const fs::path d = temp_dir("limits_counts");
  const std::string run = " --resolution 8x8 --no-progress --out " + (d / "o").string();
  REQUIRE(render("--frames 0 --ius 65536" + run).status == 0);
  refused(render("--frames 0 --ius 65537" + run), {"--ius: 65537: value 65537 is out of range [1, 65536]"});
  refused(render("--frames 0 --ius 99999999999999999999999" + run), {"--ius", "out of range [1, 65536]"});
  refused(render("--frames 0 --ius 0" + run), {"--ius: 0: value 0 is out of range [1, 65536]"});

  REQUIRE(render("--frames 59" + run).status == 0);
  refused(render("--frames 60" + run), {"--frames: 60: scene has frames 0:59 only"});
  // Past the old 9-digit parser: the same message as one frame past the scene.
  refused(render("--frames 0:1000000000" + run), {"--frames: 0:1000000000: scene has frames 0:59 only"});
  refused(render("--frames 0:99999999999" + run), {"--frames: 0:99999999999: value 99999999999 is out of range [0, 2147483647]"});

  REQUIRE(render("--frames 0 --no-progress --resolution 16384x1 --out " + (d / "o").string()).status == 0);
  refused(render("--frames 0 --no-progress --resolution 16385x1 --out " + (d / "o").string()),
          {"--resolution: 16385x1: value 16385 is out of range [1, 16384]"});

  REQUIRE(render("--frames 0 --level lt --quantum 18446744073709551615ps" + run).status == 0);
  refused(render("--frames 0 --level lt --quantum 18446744073709551616ps" + run), {"--quantum", "more than 2^64 - 1 ps"});
  refused(render("--frames 0 --level lt --quantum 0.5ps" + run), {"--quantum", "not a whole number of picoseconds"});

  const std::string vcd = " --vcd " + (d / "t.vcd").string();
  refused(render("--frames 0 --trace-buffer 4294967297" + vcd + run), {"--trace-buffer: 4294967297: value 4294967297 is out of range [1, 4294967296]"});
  refused(render("--frames 0 --threads 4097" + run), {"--threads: 4097: value 4097 is out of range [1, 4096]"});
  refused(render("--frames 0 --subdivide 4097" + run), {"--subdivide: 4097: value 4097 is out of range [1, 4096]"});
}

TEST_CASE("limits: counts in the scene file, at and past their limits", "[cli][limits]") {
  const fs::path d = temp_dir("limits_scene");
  const std::string box = R"({"name": "b", "mesh": {"generate": {"kind": "box"}}})";
  const std::string out = " --no-progress --out " + (d / "o").string();
  REQUIRE(run_oprt("render " + generated(d, "f1m", box, 1000000) + " --frames 999999 --ius 1" + out).status == 0);
  refused(run_oprt("render " + generated(d, "f1m1", box, 1000001) + " --ius 1" + out),
          {"f1m1.json: /frames: value 1000001 is out of range [1, 1000000]"});
  refused(run_oprt("render " + generated(d, "ffar", box, 1) + " --ius 1 --frames 99999999999" + out),
          {"--frames: 99999999999: value 99999999999 is out of range [0, 2147483647]"});
  const auto sized = [&](const std::string& name, const std::string& width) {
    return write(d / (name + ".json"),
                 R"({"format": "oprt-scene/1", "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]},
                     "image": {"width": )" + width + R"(, "height": 1}, "objects": [)" + box + "]}");
  };
  REQUIRE(run_oprt("render " + sized("w16384", "16384") + " --ius 1" + out).status == 0);
  refused(run_oprt("render " + sized("w16385", "16385") + " --ius 1" + out),
          {"w16385.json: /image/width: value 16385 is out of range [1, 16384]"});
  refused(run_oprt("render " + sized("w1e20", "1e20") + " --ius 1" + out),
          {"w1e20.json: /image/width: value 1e+20 is out of range [1, 16384]"});
  // A generator's counts: at the limit (refused for the triangles it would make), past it.
  refused(run_oprt("render " + generated(d, "s24", R"({"mesh": {"generate": {"kind": "sphere", "segments": 16777216}}})") + out),
          {"s24.json: /objects/0/mesh/generate: this generator would make 234881024 triangles, more than the 33554432 the "
           "scene may still have"});
  refused(run_oprt("render " + generated(d, "s25", R"({"mesh": {"generate": {"kind": "sphere", "segments": 16777217}}})") + out),
          {"s25.json: /objects/0/mesh/generate/segments: value 16777217 is out of range [3, 16777216]"});
}

TEST_CASE("limits: finding 3 - memory a generated scene cannot have is refused before it is made", "[cli][limits][memory]") {
  const fs::path d = temp_dir("limits_memory");
  // A 4096 x 4048 plane: 33,161,216 triangles, under the 2^25 a scene may have, about 6 GB.
  const std::string plane = generated(d, "plane", R"({"mesh": {"generate": {"kind": "plane", "nx": 4096, "nz": 4048}}})");
  const Measured m = run_measured({"render", plane, "--max-memory", "4G", "--out", (d / "o").string()}, d / "log");
  INFO(m.output);
  CHECK(m.status == 2);
  CHECK_THAT(m.output, Catch::Contains("plane.json: /objects/0/mesh/generate: this generator would make 33161216 "
                                       "triangles and 16588753 vertices"));
  CHECK_THAT(m.output, Catch::Contains("more than the 4 GiB it may use (--max-memory 4G)"));
  if (kMeasuresMemory) CHECK(m.peak_kb < 100 * 1024);  // nothing of it was allocated
  CHECK_FALSE(fs::exists(d / "o"));

  // Finding 10: two clouds of 2^24 each pass the triangle limit together, and need about 12 GiB.
  const std::string cloud = R"({"mesh": {"generate": {"kind": "triangle_cloud", "count": 16777216}}})";
  refused(run_oprt("render " + generated(d, "clouds", cloud + ", " + cloud) + " --max-memory 4G --out " + (d / "o").string()),
          {"clouds.json: /objects/0/mesh/generate: this generator would make 16777216 triangles", "more than the 4 GiB"});
  // The budget is the scene's, not a generator's: two clouds that fit one by one, refused at the
  // second (at 2^18 triangles each, so that the first is made quickly).
  const std::string small = R"({"mesh": {"generate": {"kind": "triangle_cloud", "count": 262144}}})";
  refused(run_oprt("render " + generated(d, "two", small + ", " + small) + " --max-memory 200M --out " + (d / "o").string()),
          {"two.json: /objects/1/mesh/generate: this generator would make 262144 triangles",
           "with 262144 triangles before it", "more than the 200 MiB it may use"});
  // A 4096 x 4096 plane with --accel bvh at 8x8: the geometry is named, not the resolution.
  const std::string square = generated(d, "square", R"({"mesh": {"generate": {"kind": "plane", "nx": 4096, "nz": 4096}}})");
  const Result bvh = run_oprt("render " + square + " --accel bvh --max-memory 4G --out " + (d / "o").string());
  refused(bvh, {"square.json: /objects/0/mesh/generate", "250 bytes a triangle"});
  CHECK_THAT(bvh.output, !Catch::Contains("--resolution"));
}

TEST_CASE("limits: finding 4 - a 16384x16384 frame is refused up front with its estimate", "[cli][limits][memory]") {
  const fs::path d = temp_dir("limits_resolution");
  const Measured m = run_measured({"render", scene("paper_room.json"), "--frames", "0", "--resolution", "16384x16384",
                                   "--max-memory", "64G", "--out", (d / "o").string()},
                                  d / "log");
  INFO(m.output);
  CHECK(m.status == 2);
  CHECK_THAT(m.output, Catch::Contains("--resolution: 16384x16384: the run would need about"));
  CHECK_THAT(m.output, Catch::Contains("the rays and image of a frame (268435456 pixels"));
  CHECK_THAT(m.output, Catch::Contains("more than the 64 GiB it may use (--max-memory 64G)"));
  if (kMeasuresMemory) CHECK(m.peak_kb < 100 * 1024);
}

TEST_CASE("limits: a request just under the limit runs, one byte over is refused", "[cli][limits][memory]") {
  const fs::path d = temp_dir("limits_under");
  const std::string run = "--frames 0 --resolution 16x16 --no-progress --out " + (d / "o").string();
  // --check prints the estimate of the whole run (the scene loaded, its lights known).
  const Result probe = render(run + " --check");
  REQUIRE(probe.status == 0);
  const std::uint64_t need = estimate_in(probe.output);
  CHECK(render(run + " --max-memory " + std::to_string(need)).status == 0);
  refused(render(run + " --max-memory " + std::to_string(need - 1)), {"more than the"});
}

TEST_CASE("limits: finding 5 - a deep ray FIFO reserves nothing it does not hold", "[cli][limits][memory]") {
  const fs::path d = temp_dir("limits_fifo");
  const std::string arch = write(d / "deep.json", R"({"format": "oprt-arch/1", "ray_fifo_depth": 16777216})");
  const Measured m = run_measured({"render", scene("paper_room.json"), "--arch", arch, "--frames", "0", "--resolution",
                                   "8x8", "--no-progress", "--out", (d / "o").string()},
                                  d / "log");
  INFO(m.output);
  CHECK(m.status == 0);
  // Before: 16,777,216 pop times of 8 bytes reserved in each of 32 FIFOs, 4.2 GB.
  if (kMeasuresMemory) CHECK(m.peak_kb < 300 * 1024);
}

TEST_CASE("limits: findings 1 to 3 - outputs that cannot be written are refused before anything is written",
          "[cli][limits][outputs]") {
  const fs::path d = temp_dir("limits_outputs");
  const fs::path o = d / "o";
  const std::string run = "--frames 0 --resolution 8x8 --no-progress --out " + o.string();
  // Finding 1: devices and pipes are never replaced.
  refused(render(run + " --timeline /dev/null"), {"--timeline: /dev/null: is a device (oprt replaces only regular files)"});
  CHECK(fs::is_character_file("/dev/null"));
  REQUIRE(mkfifo((d / "pipe").c_str(), 0644) == 0);
  refused(render(run + " --vcd " + (d / "pipe").string()), {"--vcd: " + (d / "pipe").string() + ": is a named pipe"});
  CHECK(fs::is_fifo(d / "pipe"));
  // Finding 3: a folder where a file goes, a file where a folder goes, a file where its folder goes.
  fs::create_directories(d / "folder");
  refused(render(run + " --vcd " + (d / "folder").string()), {"--vcd: " + (d / "folder").string() + ": is a folder, not a file"});
  write(d / "file", "x");
  refused(render("--frames 0 --resolution 8x8 --no-progress --out " + (d / "file").string()),
          {"--out: " + (d / "file").string() + ": is a file, not a folder"});
  refused(render(run + " --timeline " + (d / "file" / "x.json").string()), {"--timeline: ", "its folder", "is a file"});
  // Finding 2: two outputs on one path.
  refused(render(run + " --vcd " + (o / "x.vcd").string() + " --timeline " + (o / "x.vcd").string()),
          {"--timeline: " + (o / "x.vcd").string() + ": is also the file --vcd", "two outputs cannot share one path"});
  refused(render(run + " --vcd " + (o / "frame_0000.exr").string()), {"--vcd: ", "is also the file of frame 0 that --out"});
  refused(render(run + " --timeline " + (o / "stats.json").string()), {"--timeline: ", "is also the stats.json that --out"});
  refused(render(run + " --vcd " + (d / "t.vcd").string() + " --timeline " + (d / "t.gtkw").string()),
          {"--timeline: ", "is also the t.gtkw that --vcd"});
  refused(render(run + " --vcd " + (d / "t.gtkw").string()), {"--vcd: ", "the two would be one file"});
  refused(render(run + " --vcd " + (o / "x.vcd").string() + " --timeline " + o.string()), {"--timeline: ", "two outputs"});
  // An output over an input.
  refused(render(run + " --vcd " + scene("paper_room.json")), {"is the scene file this run reads"});
  CHECK_FALSE(fs::exists(o));  // nothing was written for any of them
  // A name the run writes that is not a regular file in --out.
  fs::create_directories(o / "stats.json");
  refused(render(run), {"--out: " + o.string() + ": stats.json in it is a folder, not a file"});
  if (geteuid() != 0) {  // root may write anything
    write(d / "ro.vcd", "old");
    fs::permissions(d / "ro.vcd", fs::perms::owner_read);
    refused(render(run + " --vcd " + (d / "ro.vcd").string()), {"read-only"});
  }
}

// Issue 32: an output under a folder that cannot be created (/proc refuses new folders, even
// to root, whom access() lets write anywhere) ended with exit status 1 and a raw
// std::filesystem error; it is bad input, named by its option, and the run leaves nothing.
TEST_CASE("limits: an output under a folder that cannot be created exits 2 naming the option",
          "[cli][limits][outputs]") {
  const fs::path d = temp_dir("limits_mkdir");
  const fs::path o = d / "o";
  const std::string small = "--frames 0 --resolution 8x8 --no-progress ";
  refused(render(small + "--out /proc/nonexistent/x"), {"--out: /proc/nonexistent/x: "});
  refused(render(small + "--out " + o.string() + " --vcd /proc/nonexistent/x.vcd"), {"--vcd: /proc/nonexistent/x.vcd: "});
  refused(render(small + "--out " + o.string() + " --timeline /proc/nonexistent/x.json"),
          {"--timeline: /proc/nonexistent/x.json: "});
  // A folder created for --out before --vcd's failed is removed again.
  CHECK_FALSE(fs::exists(o));
  if (geteuid() == 0) {  // root passes check(): the folder's creation itself fails, and says so
    const Result r = render(small + "--out " + o.string() + " --vcd /proc/nonexistent/x.vcd");
    CHECK_THAT(r.output, Catch::Contains("cannot create the folder /proc/nonexistent"));
    CHECK_THAT(r.output, !Catch::Contains("filesystem error"));
  }
  // reference --out too.
  const Result r = run_oprt("reference " + scene("paper_room.json") + " --frames 0 --resolution 8x8 --out /proc/nonexistent/x");
  INFO(r.output);
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("--out: /proc/nonexistent/x: "));
}

TEST_CASE("limits: findings 6 and 7 - simulated time and cycle counts that do not fit are refused naming the setting",
          "[cli][limits][overflow]") {
  const fs::path d = temp_dir("limits_time");
  const std::string run = "--frames 0 --resolution 64x64 --no-progress --out " + (d / "o").string();
  const std::string slow = write(d / "slow.json", R"({"format": "oprt-arch/1", "clock_mhz": 0.001,
      "costs": {"sphere": 100000, "transform": 100000, "triangle": [100000, 100000, 100000, 100000]}})");
  for (const char* level : {"at", "lt"}) {
    INFO(level);
    refused(render(run + " --level " + level + " --arch " + slow),
            {"slow.json: /clock_mhz and /costs: in frame 0", "2^64 - 1 ps", "a cycle is 1ms", "--level analytic"});
  }
  // The analytic level counts cycles, not picoseconds: the same frame has a cycle count.
  REQUIRE(render(run + " --level analytic --arch " + slow).status == 0);
  CHECK(stats(d / "o")["frames"][0]["makespan_cycles"].get<std::uint64_t>() > (std::uint64_t{1} << 32));

  const std::string big = write(d / "big.json", R"({"format": "oprt-arch/1",
      "costs": {"sphere": 1000000, "transform": 1000000, "triangle": [1000000, 1000000, 1000000, 1000000]}})");
  for (const char* level : {"at", "analytic"}) {
    INFO(level);
    const Result r = render(run + " --level " + level + " --arch " + big);
    refused(r, {"big.json: /costs: one unit's work on one ray would be", "more than the 2^32 - 1"});
    CHECK_THAT(r.output, !Catch::Contains("In process"));
  }
}

TEST_CASE("limits: finding 8 - a one-pixel render of one box runs at every level", "[cli][limits]") {
  const fs::path d = temp_dir("limits_box");
  const std::string box = write(d / "box.json", R"({"format": "oprt-scene/1",
      "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]}, "image": {"width": 1, "height": 1},
      "lights": [{"position": [3, 5, 4], "color": [1, 1, 1]}],
      "objects": [{"mesh": {"generate": {"kind": "box"}}}]})");
  for (const char* level : {"at", "lt", "analytic"}) {
    INFO(level);
    const Result r = run_oprt("render " + box + " --no-progress --level " + level + " --out " + (d / level).string());
    INFO(r.output);
    REQUIRE(r.status == 0);
    const auto f = stats(d / level)["frames"][0];
    CHECK(f["rays"]["primary"] == 1);
    CHECK(f["energy_j"]["ray_fifo"].is_number());  // charged: the FIFO held the ray
    CHECK(f["energy_j"]["ray_fifo"].get<double>() > 0);
  }
}

TEST_CASE("limits: finding 9 - technology values that do not fit a double are refused naming the key", "[cli][limits]") {
  const fs::path d = temp_dir("limits_tech");
  std::ifstream in(std::string(OPRT_SOURCE_DIR) + "/testbench/tech/65nm.json");
  const nlohmann::json base = nlohmann::json::parse(in);
  nlohmann::json kib = base, pj = base, edge = base;
  kib["sram"]["read_energy"][0]["capacity"]["value"] = 1e308;
  kib["sram"]["read_energy"][0]["capacity"]["unit"] = "KiB";
  pj["fp_add"]["energy"]["value"] = 1e308;
  pj["fp_add"]["energy"]["unit"] = "pJ";
  edge["fp_add"]["energy"]["value"] = 1e30;  // at the limit: runs, and every figure is a number
  edge["fp_add"]["energy"]["unit"] = "pJ";
  const std::string run = "--frames 0 --resolution 8x8 --no-progress --out " + (d / "o").string();
  refused(render(run + " --tech " + write(d / "kib.json", kib.dump())),
          {"kib.json: /sram/read_energy/0/capacity/value: value 1e+308 KiB", "outside the range a table may hold, [1e-30, 1e+30] bytes"});
  refused(render(run + " --tech " + write(d / "pj.json", pj.dump())),
          {"pj.json: /fp_add/energy/value: value 1e+308 pJ", "[1e-30, 1e+30] pJ"});
  REQUIRE(render(run + " --tech " + write(d / "edge.json", edge.dump())).status == 0);
  const auto e = stats(d / "o")["frames"][0]["energy_j"];
  CHECK(e["total"].is_number());
  CHECK(e["fp_add"].is_number());
}

TEST_CASE("limits: finding 11 - a long run's time and memory per frame do not grow with the frame number",
          "[cli][limits][long]") {
  const fs::path d = temp_dir("limits_long");
  const std::string scene_file = generated(
      d, "long",
      R"({"mesh": {"generate": {"kind": "sphere"}}, "animation": {"keyframes": [{"frame": 0, "translate": [0, 0, 0]},
          {"frame": 999999, "translate": [1, 0, 0]}]}})",
      1000000);
  const auto run = [&](const std::string& frames, const std::string& out) {
    return run_measured({"render", scene_file, "--frames", frames, "--resolution", "2x2", "--ius", "2", "--no-progress",
                         "--out", (d / out).string()},
                        d / (out + ".log"));
  };
  const Measured a = run("0:99", "a"), b = run("0:999", "b"), c = run("999000:999999", "c");
  REQUIRE(a.status == 0);
  REQUIRE(b.status == 0);
  REQUIRE(c.status == 0);
  const auto sb = stats(d / "b");
  CHECK(sb["frames"].size() == 1000);
  CHECK(sb["summary"]["frames"] == 1000);
  CHECK(sb["frames"][999]["frame"] == 999);
  std::ifstream csv(d / "b" / "stats.csv");
  CHECK(std::count(std::istreambuf_iterator<char>(csv), std::istreambuf_iterator<char>(), '\n') == 1 + 1000 * 1);
  if (kMeasuresMemory) {  // stats.json is spooled, not rebuilt in memory after every frame
    CHECK(b.peak_kb <= a.peak_kb * 11 / 10);
    CHECK(c.peak_kb <= a.peak_kb * 11 / 10);
  }
}

TEST_CASE("limits: finding 12 - compare refuses a pipe instead of blocking on it", "[cli][limits]") {
  const fs::path d = temp_dir("limits_compare");
  REQUIRE(mkfifo((d / "a.exr").c_str(), 0644) == 0);
  const Result r = run_oprt("compare " + (d / "a.exr").string() + " " + (d / "a.exr").string());
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains("a.exr: is not a regular file"));
}

TEST_CASE("limits: messages name what set a refused combination", "[cli][limits]") {
  const fs::path d = temp_dir("limits_origin");
  const std::string run = "--frames 0 --resolution 8x8 --no-progress --out " + (d / "o").string();
  const Result flags = render(run + " --balance sa_n --locality 0.5");
  refused(flags, {"--locality 0.5 with --balance sa_n:"});
  CHECK_THAT(flags.output, !Catch::Contains("built-in defaults"));
  const std::string spatial = write(d / "spatial.json", R"({"format": "oprt-arch/1", "balance": {"policy": "spatial", "locality": 0.25}})");
  refused(render(run + " --balance sa_n --arch " + spatial), {spatial + ": /balance/locality 0.25 with --balance sa_n:"});
  const std::string both = write(d / "both.json", R"({"format": "oprt-arch/1", "balance": {"policy": "sa_n", "locality": 0.25}})");
  const Result file = render(run + " --arch " + both);
  CHECK(file.status == 2);
  CHECK_THAT(file.output, Catch::Contains("locality"));
  const std::string other = write(d / "other.json", R"({"format": "oprt-arch/1", "ius": 4})");
  const Result r = render(run + " --balance paper --locality 1 --arch " + other);
  refused(r, {"--locality 1 with --balance paper:"});
  CHECK_THAT(r.output, !Catch::Contains("other.json"));
}
