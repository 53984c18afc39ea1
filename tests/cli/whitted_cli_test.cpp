// Whitted's recursion (issue 29) from the command line: the depth bound's options and their
// errors, the reference's and the timed model's ray counts per kind and per depth at every
// level on the kitchen, and the GPP issuing a spawned ray only after its parent is shaded
// (read from the timeline, the parents known from a trace of the same frame in this process).
#include "cli_util.h"
#include "ref/frame_trace.h"
#include "ref/image.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <numeric>

using namespace oprt::test;

namespace {
const std::string kWhitted = std::string(OPRT_SOURCE_DIR) + "/tests/data/scenes/whitted.json";
const std::string kKitchen = std::string(OPRT_SHARED_DIR) + "/bart/kitchen/kitchen.aff";

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// whitted.json with "depth" set to `depth` (a JSON value as text).
fs::path whitted_with_depth(const fs::path& dir, const std::string& name, const std::string& depth) {
  nlohmann::json s = nlohmann::json::parse(bytes_of(kWhitted));
  s["depth"] = nlohmann::json::parse(depth);
  const fs::path p = dir / name;
  write(p, s.dump());
  return p;
}

fs::path arch_with_depth(const fs::path& dir, const std::string& name, const std::string& depth) {
  const fs::path p = dir / name;
  write(p, R"({"format": "oprt-arch/1", "gpp": {"depth": )" + depth + "}}");
  return p;
}

// The deepest row of a frame's rays per depth (render: ray_kinds.by_depth, reference: by_depth).
int deepest(const nlohmann::json& by_depth) { return static_cast<int>(by_depth.size()) - 1; }
}  // namespace

TEST_CASE("whitted cli: --depth out of range or not a whole number exits 2 naming the option", "[cli][whitted]") {
  const fs::path d = temp_dir("whitted_depth_option");
  for (const char* bad : {"17", "-1", "x", "2.5", "1e3", ""}) {
    for (const char* cmd : {"render", "reference"}) {
      INFO(cmd << " --depth '" << bad << "'");
      const fs::path out = d / "out";
      const Result r = run_oprt(std::string(cmd) + " " + kWhitted + " --depth '" + bad + "' --out " + out.string());
      CHECK(r.status == 2);
      CHECK(r.output.find("--depth") != std::string::npos);
      CHECK_FALSE(fs::exists(out / "stats.json"));
      CHECK_FALSE(fs::exists(out / "reference.json"));
    }
  }
  // The bounds themselves are accepted.
  for (const char* ok : {"0", "16"}) {
    INFO("--depth " << ok);
    CHECK(run_oprt("reference " + kWhitted + " --resolution 4x3 --depth " + ok + " --out " + (d / "ok").string()).status ==
          0);
  }
}

TEST_CASE("whitted cli: the scene's depth and the architecture's gpp.depth are checked, naming file and place",
          "[cli][whitted]") {
  const fs::path d = temp_dir("whitted_depth_files");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"17", "out of range"}, {"-1", "out of range"}, {"\"5\"", "expected an integer"}, {"2.5", "expected an integer"}};
  int i = 0;
  for (const auto& [value, problem] : bad) {
    INFO("depth " << value);
    const fs::path scene = whitted_with_depth(d, "scene" + std::to_string(i) + ".json", value);
    for (const char* cmd : {"render", "reference"}) {
      const Result r = run_oprt(std::string(cmd) + " " + scene.string() + " --out " + (d / "out").string());
      CHECK(r.status == 2);
      CHECK(r.output.find(scene.string() + ": /depth: ") != std::string::npos);
      CHECK(r.output.find(problem) != std::string::npos);
    }
    const fs::path arch = arch_with_depth(d, "arch" + std::to_string(i) + ".json", value);
    const Result r = run_oprt("render " + kWhitted + " --arch " + arch.string() + " --out " + (d / "out").string());
    CHECK(r.status == 2);
    CHECK(r.output.find(arch.string() + ": /gpp/depth: ") != std::string::npos);
    CHECK(r.output.find(problem) != std::string::npos);
    ++i;
  }
  CHECK_FALSE(fs::exists(d / "out" / "stats.json"));
  CHECK_FALSE(fs::exists(d / "out" / "reference.json"));
}

TEST_CASE("whitted cli: the depth bound is --depth, else gpp.depth, else the scene's, else 5", "[cli][whitted]") {
  const fs::path d = temp_dir("whitted_precedence");
  const fs::path scene2 = whitted_with_depth(d, "scene2.json", "2");
  const fs::path arch3 = arch_with_depth(d, "arch3.json", "3");
  const fs::path arch0 = arch_with_depth(d, "arch0.json", "0");
  const std::string small = " --resolution 24x18";
  // The reference's rays per kind at each bound, to compare the renders with.
  std::map<int, nlohmann::json> reference;
  for (int depth : {0, 1, 2, 3, 5}) {
    const fs::path out = d / ("ref" + std::to_string(depth));
    REQUIRE(run_oprt("reference " + kWhitted + small + " --depth " + std::to_string(depth) + " --out " + out.string())
                .status == 0);
    const nlohmann::json f = stats(out, "reference.json")["frames"][0];
    CHECK(f["depth"] == depth);
    CHECK(deepest(f["by_depth"]) == depth);  // every depth is reached in this scene
    reference[depth] = f["rays"];
  }
  // Each bound gives more rays than the one below it.
  for (int depth : {1, 2, 3, 5}) CHECK(reference[depth]["reflection"] > reference[depth == 5 ? 3 : depth - 1]["reflection"]);
  CHECK(reference[0]["reflection"] == 0);
  CHECK(reference[0]["refraction"] == 0);

  struct Case {
    std::string args;
    int depth;
  };
  const std::vector<Case> cases = {
      {kWhitted, 5},                                                    // nothing said: 5
      {scene2.string(), 2},                                             // the scene's
      {scene2.string() + " --arch " + arch3.string(), 3},               // the architecture over the scene
      {scene2.string() + " --arch " + arch3.string() + " --depth 1", 1},  // the command line over both
      {scene2.string() + " --arch " + arch0.string(), 0},               // 0 is a bound, not "unset"
      {kWhitted + " --depth 0", 0},
  };
  int i = 0;
  for (const Case& c : cases) {
    INFO(c.args);
    const fs::path out = d / ("render" + std::to_string(i++));
    REQUIRE(run_oprt("render " + c.args + small + " --ius 3 --level analytic --no-progress --out " + out.string()).status ==
            0);
    CHECK(stats(out)["arch"]["gpp"]["depth"] == c.depth);  // the bound, resolved
    const nlohmann::json f = stats(out)["frames"][0];
    CHECK(deepest(f["ray_kinds"]["by_depth"]) == c.depth);
    for (const char* kind : {"primary", "shadow", "reflection", "refraction"})
      CHECK(f["rays"].value(kind, 0) == reference[c.depth][kind]);
  }
  // The reference: --depth over the scene's.
  const fs::path out = d / "ref_scene2";
  REQUIRE(run_oprt("reference " + scene2.string() + small + " --out " + out.string()).status == 0);
  CHECK(stats(out, "reference.json")["frames"][0]["depth"] == 2);
  REQUIRE(run_oprt("reference " + scene2.string() + small + " --depth 3 --out " + out.string()).status == 0);
  CHECK(stats(out, "reference.json")["frames"][0]["depth"] == 3);
}

TEST_CASE("whitted cli: reference.json lists the rays per kind and per depth, and the depth bound", "[cli][whitted]") {
  const fs::path d = temp_dir("whitted_reference_json");
  REQUIRE(run_oprt("reference " + kWhitted + " --out " + d.string()).status == 0);
  const nlohmann::json f = stats(d, "reference.json")["frames"][0];
  CHECK(f["depth"] == 5);
  const int pixels = 48 * 36;
  CHECK(f["rays"]["primary"] == pixels);
  REQUIRE(f["by_depth"].size() == 6);
  CHECK(f["by_depth"][0]["primary"] == pixels);
  CHECK(f["by_depth"][0]["reflection"] == 0);  // a secondary ray is at least one bounce deep
  CHECK(f["by_depth"][0]["refraction"] == 0);
  for (const char* kind : {"primary", "shadow", "reflection", "refraction"}) {
    INFO(kind);
    CHECK(f["rays"][kind] > 0);
    std::uint64_t sum = 0;
    for (std::size_t depth = 0; depth < f["by_depth"].size(); ++depth) {
      CHECK(f["by_depth"][depth]["depth"] == depth);
      sum += f["by_depth"][depth][kind].get<std::uint64_t>();
    }
    CHECK(sum == f["rays"][kind]);
    // One unit holding the 7 objects' spheres: a nearest-hit ray tests them all (a shadow
    // ray stops at its occluder).
    if (std::string(kind) != "shadow") CHECK(f["work"][kind]["sphere_tests"] == f["rays"][kind].get<std::uint64_t>() * 7);
  }
  for (std::size_t depth = 1; depth < 6; ++depth) CHECK(f["by_depth"][depth]["primary"] == 0);
}

TEST_CASE("whitted cli: on the kitchen at depth 5 every level issues the reference's rays per kind and depth, and "
          "renders its image",
          "[cli][whitted][kitchen]") {
  const fs::path d = temp_dir("whitted_kitchen");
  const std::string common = kKitchen + " --frames 0 --resolution 48x36 --depth 5";
  REQUIRE(run_oprt("reference " + common + " --out " + (d / "ref").string()).status == 0);
  const nlohmann::json ref = stats(d / "ref", "reference.json")["frames"][0];
  const auto reference = oprt::read_exr((d / "ref" / "frame_0000.exr").string());
  // The kitchen's glasses and chrome spawn both kinds, to the bound.
  REQUIRE(ref["rays"]["reflection"] > 0);
  REQUIRE(ref["rays"]["refraction"] > 0);
  CHECK(deepest(ref["by_depth"]) == 5);
  for (const char* level : {"at", "lt", "analytic"}) {
    INFO(level);
    const fs::path out = d / level;
    REQUIRE(run_oprt("render " + common + " --ius 8 --level " + level + " --no-progress --out " + out.string()).status ==
            0);
    const nlohmann::json f = stats(out)["frames"][0];
    CHECK(f["rays"] == ref["rays"]);
    CHECK(f["ray_kinds"]["by_depth"] == ref["by_depth"]);
    for (const char* kind : {"primary", "shadow", "reflection", "refraction"})
      CHECK(f["ray_kinds"]["kinds"][kind]["rays"] == ref["rays"][kind]);
    CHECK(oprt::read_exr((out / "frame_0000.exr").string()) == reference);
  }
}

namespace {
// A frame's ray trees as trace_pixel builds them, with ids as the timed model numbers them
// (pixel by pixel, each pixel's rays in the order they are traced): per ray its kind, depth
// and the children its hit spawned.
struct TreeRecorder : oprt::RecorderBase {
  struct Node {
    oprt::RayKind kind;
    int depth;
    std::uint32_t first_child = 0, children = 0;  // absolute ids
  };
  std::vector<Node> rays;
  template <typename Ray>
  void begin_ray(const Ray&, oprt::RayKind k, std::size_t, int depth) {
    rays.push_back({k, depth});
  }
  template <typename End>
  void end_ray(const End& e) {
    const auto id = static_cast<std::uint32_t>(rays.size() - 1);
    if (e.children) rays.back().first_child = id + e.first_child, rays.back().children = e.children;
  }
};

std::vector<TreeRecorder::Node> ray_trees(const std::string& path, int width, int height) {
  using namespace oprt;
  const Scene s = load_scene(path);
  const auto g = build_geometry<float>(s, make_spheres(s, 1));
  const FrameSetup<float> f = setup_frame(s, g, 0);
  const CameraRays camera(f.camera, width, height);
  const Shader<float> shader(s, f, -1);
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  std::vector<IuRegisters<float>> one_unit(1);
  one_unit[0].load(f, g, all);
  const FrameTraceInputs<float> in{g, one_unit, camera, shader};
  FrameImage image(width, height);
  PixelScratch<float> scratch;
  TreeRecorder rec;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) trace_pixel(in, x, y, image, rec, scratch);
  return rec.rays;
}

struct Slice {
  std::int64_t start = -1, end = -1;  // picoseconds
};
}  // namespace

TEST_CASE("whitted cli: the GPP issues a spawned ray only after its parent's shading, at and lt", "[cli][whitted][timeline]") {
  const fs::path d = temp_dir("whitted_timeline");
  const int w = 24, h = 18;
  const auto trees = ray_trees(kWhitted, w, h);
  // The GPP spends 4 cycles issuing a ray and 30 shading a hit, so that both show as slices.
  const fs::path arch = d / "gpp.json";
  write(arch, R"({"format": "oprt-arch/1", "gpp": {"cycles_per_ray": 4, "cycles_per_hit": 30}})");
  for (const char* level : {"at", "lt"}) {
    INFO(level);
    const fs::path out = d / level;
    REQUIRE(run_oprt("render " + kWhitted + " --resolution " + std::to_string(w) + "x" + std::to_string(h) +
                     " --ius 4 --arch " + arch.string() + " --level " + level + " --timeline " +
                     (d / (std::string(level) + ".json")).string() + " --no-progress --out " + out.string())
                .status == 0);
    const nlohmann::json t = nlohmann::json::parse(bytes_of(d / (std::string(level) + ".json")));
    std::vector<Slice> issue(trees.size()), shade(trees.size());
    std::size_t issues = 0, shades = 0;
    for (const auto& e : t["traceEvents"]) {
      if (e.value("ph", "") != "X" || !e.contains("args") || !e["args"].contains("ray")) continue;
      const std::string name = e["name"];
      const bool is_issue = name.rfind("issue ", 0) == 0, is_shade = name.rfind("shade ", 0) == 0;
      if (!is_issue && !is_shade) continue;
      const std::uint32_t id = e["args"]["ray"];
      REQUIRE(id < trees.size());
      const TreeRecorder::Node& n = trees[id];
      // The slice names the ray's kind and carries its depth, as the trace has them.
      CHECK(name.substr(6) == oprt::kRayKindNames[static_cast<int>(n.kind)]);
      CHECK(e["args"]["depth"] == n.depth);
      const auto ps = [](double us) { return static_cast<std::int64_t>(std::llround(us * 1e6)); };
      const Slice s{ps(e["ts"].get<double>()), ps(e["ts"].get<double>() + e["dur"].get<double>())};
      if (is_issue) {
        CHECK(issue[id].start < 0);  // once
        issue[id] = s, ++issues;
      } else {
        CHECK(oprt::seeks_nearest(n.kind));  // a shadow ray's answer is not shaded
        CHECK(shade[id].start < 0);
        shade[id] = s, ++shades;
      }
    }
    CHECK(issues == trees.size());  // every ray issued once
    std::size_t spawned = 0, parents = 0;
    for (std::uint32_t p = 0; p < trees.size(); ++p) {
      const TreeRecorder::Node& n = trees[p];
      if (!n.children) continue;
      ++parents;
      REQUIRE(shade[p].start >= 0);  // a ray whose hit spawned rays was shaded
      CHECK(shade[p].start >= issue[p].end);
      for (std::uint32_t c = n.first_child; c < n.first_child + n.children; ++c) {
        INFO("ray " << c << " (" << oprt::kRayKindNames[static_cast<int>(trees[c].kind)] << ") of parent " << p);
        CHECK(trees[c].depth == n.depth + (trees[c].kind == oprt::RayKind::shadow ? 0 : 1));
        CHECK(issue[c].start >= shade[p].end);
        ++spawned;
      }
    }
    CHECK(shades >= parents);
    CHECK(spawned == trees.size() - static_cast<std::size_t>(w * h));  // every ray but the primaries has a parent
    CHECK(spawned > 1000);
  }
}
