// render --sample: outputs a user checks against the full run, on scenes whose answer is known.
#include "cli_util.h"

#include "ref/image.h"
#include "sample/pixel_sample.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <string>

using namespace oprt::test;

namespace {

// Every ray misses every sphere: the camera looks down -z, the objects lie behind it. Each ray
// costs each unit the tests of its spheres and nothing else, so every pixel costs the same.
const char* kUniform = R"({
  "format": "oprt-scene/1",
  "camera": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0], "fov_y_deg": 40},
  "image": {"width": 36, "height": 30},
  "background": [0.2, 0.3, 0.4], "ambient": [0.1, 0.1, 0.1],
  "lights": [{"position": [0, 5, 0], "color": [1, 1, 1]}],
  "objects": [
    {"name": "a", "mesh": {"generate": {"kind": "triangle_cloud", "count": 40, "radius": 1, "size": 0.2, "seed": 1}},
     "transform": {"translate": [0, 0, 6]}},
    {"name": "b", "mesh": {"generate": {"kind": "triangle_cloud", "count": 70, "radius": 1, "size": 0.2, "seed": 2}},
     "transform": {"translate": [3, 0, 5]}},
    {"name": "c", "mesh": {"generate": {"kind": "triangle_cloud", "count": 10, "radius": 1, "size": 0.2, "seed": 3}},
     "transform": {"translate": [-3, 1, 7]}}
  ],
  "frames": 1
})";

// A wall every ray hits, and in front of it a dense cloud of 3,000 triangles a few pixels wide:
// the cloud's unit is the frame's bottleneck, its work all in a few blocks of the image.
const char* kHotSpot = R"({
  "format": "oprt-scene/1",
  "camera": {"eye": [0, 0, 8], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40},
  "image": {"width": 48, "height": 48},
  "background": [0, 0, 0], "ambient": [0.1, 0.1, 0.1],
  "lights": [{"position": [2, 3, 9], "color": [1, 1, 1]}],
  "objects": [
    {"name": "wall", "mesh": {"vertices": [[-9, -9, -1], [9, -9, -1], [9, 9, -1], [-9, 9, -1]],
                              "triangles": [[0, 1, 2], [0, 2, 3]]}},
    {"name": "cloud", "mesh": {"generate": {"kind": "triangle_cloud", "count": 3000, "radius": 0.35, "size": 0.1,
                                            "seed": 7}},
     "transform": {"translate": [0.7, 0.4, 1]}}
  ],
  "frames": 1
})";

fs::path write_scene(const fs::path& d, const char* text) {
  const fs::path p = d / "scene.json";
  std::ofstream(p) << text;
  return p;
}

nlohmann::json frame0(const fs::path& out) { return stats(out)["frames"][0]; }

Result render(const fs::path& scene, const std::string& args, const fs::path& out) {
  return run_oprt("render " + scene.string() + " --frames 0 --no-progress --threads 2 " + args + " --out " + out.string());
}

bool covers(const nlohmann::json& interval, double truth) {
  return interval[0].get<double>() <= truth && truth <= interval[1].get<double>();
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE("cli: --sample on a frame whose every pixel costs the same: exact estimates, intervals of no width",
          "[cli][sample]") {
  const fs::path d = temp_dir("sample_uniform");
  const fs::path scene = write_scene(d, kUniform);
  for (const char* level : {"analytic", "at"}) {
    INFO(level);
    const std::string args = std::string("--level ") + level + " --ius 3";
    REQUIRE(render(scene, args, d / "full").status == 0);
    // 1/16 on 36x30: blocks of 4x4, the last row of blocks 2 tall: unequal blocks, the same pixels.
    REQUIRE(render(scene, args + " --sample 1/16 --seed 5", d / "s").status == 0);
    const nlohmann::json full = frame0(d / "full"), s = frame0(d / "s")["sample"];
    CHECK(s["pixels"] == 9 * 8);
    CHECK(s["trusted"] == true);
    const nlohmann::json& e = s["estimate"];
    const nlohmann::json& i = s["interval"];
    CHECK(e["makespan_cycles"].get<double>() == Approx(full["makespan_cycles"].get<double>()).epsilon(1e-12));
    CHECK(e["energy_j"].get<double>() == Approx(full["energy_j"]["total"].get<double>()).epsilon(1e-12));
    CHECK(e["rays"].get<double>() == Approx(full["rays"]["primary"].get<double>()).epsilon(1e-12));
    for (const char* k : {"makespan_cycles", "energy_j", "busy_cycles", "bus_bytes", "rays"}) {
      INFO(k);
      CHECK(i[k][0].get<double>() == Approx(e[k].get<double>()).epsilon(1e-12));
      CHECK(i[k][1].get<double>() == Approx(e[k].get<double>()).epsilon(1e-12));
    }
    for (std::size_t u = 0; u < 3; ++u)
      CHECK(e["busy_cycles_per_unit"][u].get<double>() ==
            Approx(full["ius"][u]["busy_cycles"].get<double>()).epsilon(1e-12));
  }
}

TEST_CASE("cli: --sample with the work in a few blocks: the intervals cover the full frame's figures",
          "[cli][sample]") {
  const fs::path d = temp_dir("sample_hot");
  const fs::path scene = write_scene(d, kHotSpot);
  REQUIRE(render(scene, "--level analytic --ius 2", d / "full").status == 0);
  const nlohmann::json full = frame0(d / "full");
  double busiest = 0;
  for (const auto& u : full["ius"]) busiest = std::max(busiest, u["busy_cycles"].get<double>());
  REQUIRE(busiest > 0.9 * full["makespan_cycles"].get<double>());  // the cloud's unit sets the frame
  for (int seed = 0; seed < 5; ++seed) {
    INFO("seed " << seed);
    REQUIRE(render(scene, "--level analytic --ius 2 --sample 1/16 --seed " + std::to_string(seed), d / "s").status == 0);
    const nlohmann::json s = frame0(d / "s")["sample"];
    CHECK(covers(s["interval"]["makespan_cycles"], full["makespan_cycles"].get<double>()));
    CHECK(covers(s["interval"]["energy_j"], full["energy_j"]["total"].get<double>()));
    CHECK(covers(s["interval"]["busy_cycles"], full["busy_cycles"].get<double>()));
    // The interval is honest about the hot spot: it is wide.
    const double width = s["interval"]["makespan_cycles"][1].get<double>() - s["interval"]["makespan_cycles"][0].get<double>();
    CHECK(width > 0.02 * full["makespan_cycles"].get<double>());
  }
}

TEST_CASE("cli: --sample's pixels: each the full run's bit for bit, the others marked; the seed chooses them",
          "[cli][sample]") {
  const fs::path d = temp_dir("sample_pixels");
  const std::string room = scene("paper_room.json") + " --resolution 30x22 --ius 8";
  for (const char* level : {"analytic", "at"}) {
    INFO(level);
    const std::string args = std::string("--level ") + level;
    REQUIRE(run_oprt("render " + room + " --frames 0 --no-progress " + args + " --out " + (d / "full").string()).status == 0);
    const oprt::FrameImage full = oprt::read_exr((d / "full" / "frame_0000.exr").string());
    for (int seed : {0, 1}) {
      const fs::path out = d / ("s" + std::to_string(seed));
      REQUIRE(run_oprt("render " + room + " --frames 0 --no-progress " + args + " --sample 0.0625 --seed " +
                       std::to_string(seed) + " --out " + out.string())
                  .status == 0);
      const oprt::FrameImage img = oprt::read_exr((out / "frame_0000.exr").string());
      const oprt::PixelSample sample(30, 22, 16, static_cast<std::uint64_t>(seed));
      std::vector<char> traced(img.size(), 0);
      for (std::uint32_t p : sample.pixels()) traced[p] = 1;
      std::size_t marked = 0, equal = 0;
      for (std::size_t p = 0; p < img.size(); ++p) {
        if (traced[p]) {
          equal += same_bits(img.r[p], full.r[p]) && same_bits(img.g[p], full.g[p]) && same_bits(img.b[p], full.b[p]) &&
                   same_bits(img.z[p], full.z[p]) && img.object[p] == full.object[p] && img.prim[p] == full.prim[p];
        } else {
          marked += img.r[p] == 0 && img.g[p] == 0 && img.b[p] == 0 && std::isnan(img.z[p]) &&
                    img.object[p] == oprt::kNotTraced && img.prim[p] == oprt::kNotTraced;
        }
      }
      CHECK(sample.size() == 8 * 6);  // 30x22 in blocks of 4x4: 8 columns, 6 rows
      CHECK(equal == sample.size());
      CHECK(marked == img.size() - sample.size());
    }
    CHECK(bytes_of(d / "s0" / "frame_0000.exr") != bytes_of(d / "s1" / "frame_0000.exr"));
    REQUIRE(run_oprt("render " + room + " --frames 0 --no-progress " + args + " --sample 1/16 --seed 0 --out " +
                     (d / "again").string())
                .status == 0);
    CHECK(bytes_of(d / "again" / "frame_0000.exr") == bytes_of(d / "s0" / "frame_0000.exr"));
    CHECK(without_wall_clock(stats(d / "again")) == without_wall_clock(stats(d / "s0")));
  }
}

TEST_CASE("cli: --sample 1 is the full run, byte for byte", "[cli][sample]") {
  const fs::path d = temp_dir("sample_one");
  const std::string room = scene("paper_room.json") + " --frames 0 --resolution 24x20 --ius 6 --no-progress";
  for (const char* level : {"analytic", "at"}) {
    INFO(level);
    REQUIRE(run_oprt("render " + room + " --level " + level + " --out " + (d / "full").string()).status == 0);
    REQUIRE(run_oprt("render " + room + " --level " + level + " --sample 1 --seed 9 --out " + (d / "one").string())
                .status == 0);
    for (const char* f : {"frame_0000.exr", "frame_0000.png", "stats.csv"})
      CHECK(bytes_of(d / "one" / f) == bytes_of(d / "full" / f));
    CHECK(without_wall_clock(stats(d / "one")) == without_wall_clock(stats(d / "full")));
  }
}

TEST_CASE("cli: --sample's mistakes: one message each, exit 2", "[cli][sample]") {
  const fs::path d = temp_dir("sample_bad");
  const std::string room = "render " + scene("paper_room.json") + " --frames 0 --resolution 16x16 --out " + d.string();
  for (const char* bad : {"--sample 0.3", "--sample 0", "--sample 1/0", "--sample 2", "--sample x", "--seed 3",
                          "--sample-fifos kept", "--sample 1/16 --seed -1"}) {
    INFO(bad);
    const Result r = run_oprt(room + " " + bad);
    CHECK(r.status == 2);
  }
  CHECK(run_oprt(room + " --seed 3").output.find("--seed: 3: chooses the pixels of --sample") != std::string::npos);
  CHECK(run_oprt(room + " --sample 0.3").output.find("--sample: 0.3: not 1/N") != std::string::npos);
}

TEST_CASE("cli: an oprt batch line takes --sample", "[cli][sample][batch]") {
  const fs::path d = temp_dir("sample_batch");
  std::ofstream(d / "archs.jsonl") << R"({"args": ["--frames", "0", "--resolution", "32x32", "--sample", "1/16", "--seed", "2"]})"
                                   << "\n";
  REQUIRE(run_oprt("batch " + scene("paper_room.json") + " --archs " + (d / "archs.jsonl").string() + " --out " +
                   (d / "b").string())
              .status == 0);
  REQUIRE(run_oprt("render " + scene("paper_room.json") +
                   " --frames 0 --resolution 32x32 --sample 1/16 --seed 2 --level analytic --no-progress --out " +
                   (d / "alone").string())
              .status == 0);
  const nlohmann::json b = stats(d / "b" / "0");
  CHECK(b["frames"][0]["sample"]["pixels"] == 64);
  CHECK(without_wall_clock(b) == without_wall_clock(stats(d / "alone")));
}
