// --balance spatial and --locality as a user runs them: bad values, the architecture file's
// two forms of "balance", images (the reference's, whatever the assignment), feedback with
// and without a locality, threads, and what `oprt info` prints.
#include "balance/partition_quality.h"
#include "balance/policy.h"
#include "cli_util.h"
#include "ref/image.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <cstdio>
#include <fstream>
#include <regex>

using namespace oprt;
using namespace oprt::test;

namespace {

std::string room() { return scene("paper_room.json"); }

FrameImage image(const fs::path& dir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d.exr", frame);
  return read_exr((dir / name).string());
}

// Each frame's assignment as stats.json lists it.
Assignment assignment_of(const nlohmann::json& frame) {
  Assignment a;
  for (const auto& u : frame["ius"]) a.unit.push_back(u["spheres"].get<std::vector<std::uint32_t>>());
  return a;
}

double number_after(const std::string& text, const std::string& label) {
  std::smatch m;
  REQUIRE(std::regex_search(text, m, std::regex(label + " ([0-9.]+)")));
  return std::stod(m[1]);
}

}  // namespace

TEST_CASE("cli: --locality and the architecture file's balance object; bad values exit 2", "[cli][balance][spatial]") {
  const fs::path d = temp_dir("locality_bad");
  const std::string render = "render " + room() + " --frames 0 --resolution 8x8 --no-progress --out " + (d / "o").string();
  const std::pair<std::string, std::string> bad[] = {
      {render + " --balance sa_n --locality 0.5", "--locality: 0.5: only --balance spatial and feedback"},
      {render + " --locality 0.5", "(the balance is paper)"},
      {render + " --balance spatial --locality 1.5", "--locality: 1.5: expected a number from 0"},
      {render + " --balance spatial --locality nan", "--locality: nan: expected a number"},
      {render + " --balance spatial --locality 0.5x", "--locality: 0.5x: expected a number"},
      {render + " --balance nearest", "--balance"},
      {"info " + room() + " --balance view --locality 0", "--locality: 0: only --balance spatial and feedback"},
  };
  for (const auto& [args, message] : bad) {
    INFO(args);
    const Result r = run_oprt(args);
    CHECK(r.status == 2);
    CHECK(r.output.find(message) != std::string::npos);
  }
  const std::pair<std::string, std::string> files[] = {
      {R"({"format": "oprt-arch/1", "balance": {"policy": "sa_n", "locality": 0.5}})",
       "balance.locality with balance sa_n: only spatial and feedback take a locality"},
      {R"({"format": "oprt-arch/1", "balance": {"policy": "spatial", "locality": 2}})", "/balance/locality"},
      {R"({"format": "oprt-arch/1", "balance": {"policy": "spatial", "weight": 2}})", "/balance"},
      {R"({"format": "oprt-arch/1", "balance": {"policy": "nearest"}})", "/balance/policy"},
      {R"({"format": "oprt-arch/1", "balance": 3})", "/balance"},
  };
  for (const auto& [text, message] : files) {
    INFO(text);
    std::ofstream(d / "arch.json") << text;
    const Result r = run_oprt(render + " --arch " + (d / "arch.json").string());
    CHECK(r.status == 2);
    CHECK(r.output.find((d / "arch.json").string()) != std::string::npos);
    CHECK(r.output.find(message) != std::string::npos);
  }
}

TEST_CASE("cli: spatial renders the reference's image at every level and records its locality",
          "[cli][balance][spatial]") {
  const fs::path d = temp_dir("spatial_render");
  const std::string frames = " --subdivide 8 --frames 0:1 --resolution 32x24";
  REQUIRE(run_oprt("reference " + room() + frames + " --out " + (d / "ref").string()).status == 0);
  std::ofstream(d / "quarter.json") << R"({"format": "oprt-arch/1", "ius": 8, "balance": {"policy": "spatial", "locality": 0.25}})";
  std::ofstream(d / "knob.json") << R"({"format": "oprt-arch/1", "ius": 8, "balance": {"locality": 0.75}})";
  const std::string common = "render " + room() + frames + " --no-progress";
  const std::pair<std::string, double> runs[] = {
      {"--ius 8 --balance spatial --level at", 0.5},
      {"--ius 8 --balance spatial --level lt", 0.5},
      {"--ius 8 --balance spatial --level analytic --accel bvh --top bvh", 0.5},
      {"--arch " + (d / "quarter.json").string(), 0.25},
      {"--arch " + (d / "quarter.json").string() + " --locality 1", 1.0},  // the flag wins
      {"--arch " + (d / "knob.json").string() + " --balance spatial", 0.75},  // the file's knob, the flag's policy
  };
  int i = 0;
  for (const auto& [args, locality] : runs) {
    INFO(args);
    const fs::path out = d / std::to_string(i++);
    REQUIRE(run_oprt(common + " " + args + " --out " + out.string()).status == 0);
    const auto s = stats(out);
    CHECK(s["arch"]["balance"] == "spatial");
    CHECK(s["arch"]["locality"] == locality);
    for (int f : {0, 1}) CHECK(image(out, f) == image(d / "ref", f));
  }
  // Locality 0 is sa_n's assignment, frame by frame.
  REQUIRE(run_oprt(common + " --ius 8 --level analytic --balance sa_n --out " + (d / "sa_n").string()).status == 0);
  REQUIRE(run_oprt(common + " --ius 8 --level analytic --balance spatial --locality 0 --out " + (d / "zero").string())
              .status == 0);
  CHECK(assignment_of(stats(d / "zero")["frames"][0]).unit == assignment_of(stats(d / "sa_n")["frames"][0]).unit);
  // The records of the other policies keep their old shape: no locality.
  CHECK_FALSE(stats(d / "sa_n")["arch"].contains("locality"));
}

TEST_CASE("cli: feedback with locality 0 is feedback; with 0.5 it keeps units together and the image",
          "[cli][balance][spatial]") {
  const fs::path d = temp_dir("feedback_locality");
  const std::string common = "render " + room() + " --ius 8 --subdivide 4 --frames 0:2 --resolution 24x24 --level analytic "
                             "--balance feedback --no-progress";
  REQUIRE(run_oprt(common + " --out " + (d / "plain").string()).status == 0);
  REQUIRE(run_oprt(common + " --locality 0 --out " + (d / "zero").string()).status == 0);
  REQUIRE(run_oprt(common + " --locality 0.5 --out " + (d / "half").string()).status == 0);
  nlohmann::json plain = without_wall_clock(stats(d / "plain")), zero = without_wall_clock(stats(d / "zero"));
  CHECK(zero["arch"]["locality"] == 0.0);
  CHECK_FALSE(plain["arch"].contains("locality"));
  zero["arch"].erase("locality");
  CHECK(plain == zero);

  // Re-partitioned by place every frame: each frame's assignment, read back from stats.json,
  // has a smaller estimated fan-out than plain feedback's at that frame's positions.
  const Scene scene = load_scene(room());
  const auto spheres = make_spheres(scene, 4);
  const auto half = stats(d / "half"), fb = stats(d / "plain");
  std::uint64_t moved = 0;
  for (int f = 0; f < 3; ++f) {
    INFO("frame " << f);
    const auto boxes = sphere_world_boxes(scene, spheres, f);
    const Assignment a = assignment_of(half["frames"][f]), b = assignment_of(fb["frames"][f]);
    CHECK(a.is_partition(spheres.size()));
    CHECK(expected_fanout(unit_bounds(a, boxes), union_of(boxes)) <
          expected_fanout(unit_bounds(b, boxes), union_of(boxes)));
    CHECK(image(d / "half", f) == image(d / "plain", f));
    moved += half["frames"][f]["memory_load_bytes"].get<std::uint64_t>();
  }
  CHECK(moved > 0);  // the geometry it moves is charged as feedback's is
}

TEST_CASE("cli: spatial and feedback with a locality give the same bytes with 1 and 2 threads",
          "[cli][balance][spatial][threads]") {
  const fs::path d = temp_dir("spatial_threads");
  for (const std::string policy : {"spatial", "feedback --locality 0.5"})
    for (const char* n : {"1", "2"}) {
      const std::string out = (d / (policy.substr(0, 3) + n)).string();
      REQUIRE(run_oprt("render " + room() + " --ius 8 --subdivide 8 --frames 0:1 --resolution 24x24 --level analytic "
                       "--no-progress --balance " + policy + " --threads " + n + " --out " + out).status == 0);
    }
  for (const char* p : {"spa", "fee"}) {
    INFO(p);
    const fs::path one = d / (std::string(p) + "1"), two = d / (std::string(p) + "2");
    CHECK(without_wall_clock(stats(one)) == without_wall_clock(stats(two)));
    CHECK(bytes_of(one / "frame_0001.exr") == bytes_of(two / "frame_0001.exr"));
  }
}

TEST_CASE("cli: info prints the assignment's estimated fan-out and imbalance", "[cli][balance][spatial][info]") {
  const std::string common = "info " + room() + " --subdivide 8 --ius 32";
  // Without an assignment option, what info printed before.
  CHECK(run_oprt("info " + room() + " --subdivide 8").output.find("fan-out") == std::string::npos);
  const Scene scene = load_scene(room());
  const auto spheres = make_spheres(scene, 8);
  const auto boxes = sphere_world_boxes(scene, spheres, 0);
  const auto weights = sa_n_weights(scene, spheres);
  const std::size_t units = units_for(spheres.size(), 32);
  const std::pair<std::string, Assignment> cases[] = {
      {" --balance sa_n", static_assignment("sa_n", scene, spheres, units)},
      {" --balance spatial", static_assignment("spatial", scene, spheres, units, {}, 0.5)},
      {" --balance spatial --locality 1", static_assignment("spatial", scene, spheres, units, {}, 1)},
      {" --balance feedback --locality 0.25", static_assignment("spatial", scene, spheres, units, {}, 0.25)},
  };
  double sa_n_fanout = 0;
  for (const auto& [args, a] : cases) {
    INFO(args);
    const Result r = run_oprt(common + args);
    REQUIRE(r.status == 0);
    const PartitionQuality q = partition_quality(a, boxes, weights);
    CHECK(number_after(r.output, "fan-out") == Approx(q.fanout).margin(5e-5));
    CHECK(number_after(r.output, "imbalance") == Approx(q.imbalance).margin(5e-5));
    CHECK(r.output.find(std::to_string(spheres.size()) + " spheres on 32 units") != std::string::npos);
    if (sa_n_fanout == 0) sa_n_fanout = q.fanout;
    else CHECK(q.fanout < sa_n_fanout / 2);
  }
}

TEST_CASE("cli: spatial and feedback with a locality on a scene with deforming and hidden objects",
          "[cli][balance][spatial]") {
  // features.aff: 5 frames, triangles that move on their own (tpa) and an object with
  // visibility keys; split by extent, then in 3. More units than some frames need.
  const fs::path d = temp_dir("spatial_aff");
  const std::string aff = std::string(OPRT_SOURCE_DIR) + "/tests/data/aff/features.aff";
  REQUIRE(run_oprt("reference " + aff + " --subdivide 3 --out " + (d / "ref").string()).status == 0);
  const std::string common = "render " + aff + " --subdivide 3 --ius 6 --no-progress";
  for (const std::string run : {"spatial --level at", "spatial --locality 1 --level analytic",
                                "feedback --locality 0.5 --level at", "feedback --locality 0.75 --level analytic"}) {
    INFO(run);
    const fs::path out = d / std::to_string(std::hash<std::string>{}(run));
    REQUIRE(run_oprt(common + " --balance " + run + " --out " + out.string()).status == 0);
    const auto s = stats(out);
    REQUIRE(s["frames"].size() == 5);
    for (int f = 0; f < 5; ++f) {
      CHECK(image(out, f) == image(d / "ref", f));
      const Assignment a = assignment_of(s["frames"][f]);
      CHECK(a.is_partition(s["spheres"].get<std::size_t>()));
      for (const auto& unit : a.unit) CHECK_FALSE(unit.empty());
    }
  }
}
