// The object-memory latency model, worked by hand: brute force streams one burst; a BVH's
// node and leaf fetches are dependent bursts (ref/memory_timing.h).
#include "ref/memory_timing.h"
#include "balance/spheres.h"
#include "ref/bvh_traverse.h"
#include "scene/load.h"
#include "timing/gpp_plan.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
const std::uint32_t kTri[4] = {4, 14, 17, 22};
}

TEST_CASE("memory timing: brute force is one burst behind the transform", "[memory]") {
  StreamCosts c;
  c.latency = 10;
  c.bytes_per_cycle = 4;
  c.triangle_bytes = 48;
  c.lead = 19;
  c.triangle = kTri;
  // Triangle j arrives at 10 + 12 (j + 1) = 22, 34, 46; tests of 22 cycles start at
  // max(previous end, arrival): 22 -> 44, 44 -> 66, 66 -> 88. Work 19 + 66: 3 stalled.
  const std::uint8_t stages[] = {3, 3, 3};
  CHECK(stream_stall(c, stages, 3) == 3);
  // Fast memory: every triangle is there in time.
  c.bytes_per_cycle = 64;
  CHECK(stream_stall(c, stages, 3) == 0);
}

TEST_CASE("memory timing: BVH node and leaf fetches are dependent bursts", "[memory][bvh]") {
  StreamCosts c;
  c.latency = 10;
  c.bytes_per_cycle = 16;
  c.triangle_bytes = 48;
  c.node_bytes = 32;
  c.lead = 31;  // transform 19 + box set-up 12
  c.triangle = kTri;
  c.box = 13;
  // root: requested at the sphere hit, arrives 10 + 2 = 12, tested 31 -> 44;
  // next node: requested at 44, arrives 56, tested 56 -> 69 (12 stalled);
  // leaf triangles: requested at 69, arrive 69 + 10 + 3 = 82 and 85: 82 -> 96 (13 more),
  //   then 96 -> 118;
  // next node: requested at 118, arrives 130, tested 130 -> 143 (12 more). 37 in all.
  const std::uint8_t log[] = {kLogNode, kLogNode, 1, 3, kLogNode};
  CHECK(stream_stall(c, log, 5) == 37);
  // Zero latency and a wide memory: only the transfer of each item, hidden behind work
  // except the first triangle of the leaf (3 cycles) and each node after the first (2).
  c.latency = 0;
  CHECK(stream_stall(c, log, 5) == 2 + 3 + 2);
}

TEST_CASE("memory timing: a triangle one cycle late stalls the unit one cycle and bytes round up", "[memory]") {
  StreamCosts c;
  c.latency = 10;
  c.bytes_per_cycle = 4;
  c.triangle_bytes = 48;
  c.lead = 21;
  c.triangle = kTri;
  // The first triangle arrives at 10 + 12 = 22, the unit is free at 21: one cycle stalled;
  // then 22 -> 44 -> 66 -> 88 with the others (34, 46) in time.
  const std::uint8_t stages[] = {3, 3, 3};
  CHECK(stream_stall(c, stages, 3) == 1);
  c.lead = 22;  // free exactly when it arrives: no stall
  CHECK(stream_stall(c, stages, 3) == 0);
  // 48 bytes at 5 per cycle take 10 cycles (9.6 rounded up): the first triangle is there at
  // 20, the second at 30 (96 / 5 = 19.2: 20 cycles); with the unit free at 19, one stall.
  c.bytes_per_cycle = 5;
  c.lead = 19;
  CHECK(stream_stall(c, stages, 1) == 1);
  c.lead = 20;
  CHECK(stream_stall(c, stages, 1) == 0);
}

TEST_CASE("memory loads: a unit that gave a sphere away loads it again when it comes back", "[memory][balance]") {
  // The room's first three spheres on two units, on-chip memories (no caches). First
  // {0, 1} | {2}: both units load everything. Then {0} | {1, 2}: unit 1 writes sphere 1's
  // bytes; unit 0 writes nothing but now holds only sphere 0. Then {0, 1} | {2} again: unit 0
  // must write sphere 1's bytes once more (unit 1 writes nothing: it keeps sphere 2).
  const Scene scene = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  const SceneGeometry<float> g = build_geometry<float>(scene, make_spheres(scene, 1));
  REQUIRE(g.sphere_count() >= 3);
  Arch arch;
  arch.ius = 2;
  timing::GppPlan<float> plan(scene, g, arch);
  const auto loads = [&](const std::vector<std::vector<std::uint32_t>>& a) {
    plan.assign(a);
    std::vector<std::pair<std::uint32_t, std::uint64_t>> out;
    for (const timing::MemoryLoad& l : plan.memory_loads()) {
      CHECK_FALSE(l.cache);
      out.push_back({l.unit, l.bytes});
    }
    return out;
  };
  using Loads = std::vector<std::pair<std::uint32_t, std::uint64_t>>;
  const std::uint64_t b0 = g.memory_bytes(0), b1 = g.memory_bytes(1), b2 = g.memory_bytes(2);
  CHECK(loads({{0, 1}, {2}}) == Loads{{0, b0 + b1}, {1, b2}});
  // A unit whose spheres changed is listed even with nothing to write: its new set is what
  // it holds from now on.
  CHECK(loads({{0}, {1, 2}}) == Loads{{0, 0}, {1, b1}});
  CHECK(loads({{0, 1}, {2}}) == Loads{{0, b1}, {1, 0}});
}
