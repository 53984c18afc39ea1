// Every work counter a render writes (per unit and kind of ray: sphere, transform, box
// set-up, box, node and triangle tests, exit stages, hits) is the functional work of that
// unit on that frame, counted here independently of the timed model: the frame's pixels
// traced through the reference's traversal (ref/frame_trace.h) with each unit's registers,
// built from the assignment stats.json reports. A counter written under the wrong key, or
// summed over the wrong units or kinds, fails.
#include "cli_util.h"

#include "balance/spheres.h"
#include "ref/frame_setup.h"
#include "ref/frame_trace.h"
#include "ref/top_traverse.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

using namespace oprt;
using namespace oprt::test;

namespace {
// Per unit and kind of ray, the work of every sphere test it made, and its node tests.
struct Counter : RecorderBase {
  std::vector<std::array<WorkCounts, kRayKinds>> units;
  int kind = 0;
  std::uint32_t unit = 0;
  void begin_ray(const Ray<float>&, RayKind k, std::size_t, int) { kind = static_cast<int>(k); }
  void begin_unit(std::uint32_t u) { unit = u; }
  void visit(const SphereVisit& v) {
    WorkCounts& w = units[unit][kind];
    w.node_tests += v.nodes_before;
    if (v.sphere != kNone) w += v.work;
  }
};

void check(const nlohmann::json& j, const WorkCounts& w) {
  CHECK(j["sphere_tests"] == w.sphere_tests);
  CHECK(j["transforms"] == w.transforms);
  CHECK(j["triangle_tests"] == w.tri_tests());
  for (int s = 0; s < kTriStages; ++s) CHECK(j["triangle_exit_stage"][s] == w.tri_stage[s]);
  CHECK(j["triangle_hits"] == w.tri_hits);
  CHECK(j["box_setups"] == w.box_setups);
  CHECK(j["box_tests"] == w.box_tests);
  CHECK(j["node_tests"] == w.node_tests);
}

void counters_match(const std::string& options) {
  const fs::path d = temp_dir("work_counters");
  const int frame = 2, width = 24, height = 18;
  REQUIRE(run_oprt("render " + scene("paper_room.json") + " --frames 2 --resolution 24x18 --ius 6 --subdivide 2 "
                   "--balance sa_n --accel bvh --top bvh " + options + " --no-progress --out " + d.string())
              .status == 0);
  const nlohmann::json f = stats(d)["frames"][0];

  const Scene sc = load_scene(scene("paper_room.json"));
  const SceneGeometry<float> g =
      build_geometry<float>(sc, make_spheres(sc, 2, SplitRule::balanced_san, ObjectSplit::count), Kernel::moller, Accel::bvh);
  const FrameSetup<float> setup = setup_frame(sc, g, frame);
  std::vector<IuRegisters<float>> regs(f["ius"].size());
  std::vector<TopTree> trees(regs.size());
  for (std::size_t u = 0; u < regs.size(); ++u) {
    const auto spheres = f["ius"][u]["spheres"].get<std::vector<std::uint32_t>>();
    regs[u].load(setup, g, spheres);
    load_top(regs[u], trees[u], spheres, setup, g);
  }
  const CameraRays camera(sc.camera->at(frame), width, height);
  const Shader<float> shader(sc, setup);
  const FrameTraceInputs<float> in{g, regs, camera, shader, false};
  FrameImage image(width, height);
  PixelScratch<float> scratch;
  Counter c;
  c.units.resize(regs.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) trace_pixel(in, x, y, image, c, scratch);

  std::uint64_t boxes = 0, nodes = 0;
  for (std::size_t u = 0; u < regs.size(); ++u) {
    INFO("unit " << u);
    check(f["ius"][u]["work"]["primary"], c.units[u][0]);
    check(f["ius"][u]["work"]["shadow"], c.units[u][1]);
    boxes += c.units[u][0].box_tests + c.units[u][1].box_tests;
    nodes += c.units[u][0].node_tests + c.units[u][1].node_tests;
  }
  // Every counter is exercised: box tests and set-ups differ, node tests are there.
  CHECK(boxes > 0);
  CHECK(nodes > 0);
}
}  // namespace

TEST_CASE("work counters: a serial render's are the frame's functional work, unit by unit", "[cli][work]") {
  counters_match("--iu serial --level at");
}

TEST_CASE("work counters: a pipelined render through caches, at the analytic level, has the same", "[cli][work]") {
  counters_match("--iu pipelined --sram 4K --level analytic");
}
