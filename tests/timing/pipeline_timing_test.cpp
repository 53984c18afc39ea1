// The pipelined IU's timing (timing/pipeline_timing.h) on small cases computed by hand: each
// unit's issue slots and latency, rays that finish out of order, a later ray filling the
// slots an earlier one left free (and never delaying it), the tree's chain of tests, rays
// waiting for object memory while the units serve others, the limit on rays in flight, and
// the traversal stack's spills and fills.
#include "timing/object_memory_model.h"
#include "timing/pipeline_timing.h"

#include <catch2/catch.hpp>

#include <memory>
#include <vector>

using namespace oprt;
using namespace oprt::timing;

namespace {
// Node II 1 latency 5, sphere II 1 latency 3, transform II `t_ii` latency `t_lat`, box II 1
// latency 2, triangle II 1 latency 4.
PipelineConfig config(int in_flight, Cycle t_ii = 1, Cycle t_lat = 2) {
  PipelineConfig c;
  c.stage[0] = {true, 1, 5, {}};
  c.stage[1] = {true, 1, 3, {}};
  c.stage[2] = {true, t_ii, t_lat, {}};
  c.stage[3] = {true, 1, 2, {}};
  c.stage[4] = {true, 1, 4, {}};
  c.rays_in_flight = in_flight;
  c.stack_overflow_cycles = 10;
  return c;
}

// An object memory without a cache: ideal (data at the request), or a latency of 10 cycles
// streaming `bytes_per_cycle`.
struct Memory final : VisitReader {
  Arch arch;
  std::unique_ptr<ObjectMemoryModel> model;
  explicit Memory(int bytes_per_cycle = 0) {
    if (bytes_per_cycle) {
      arch.memory.model = MemoryModel::latency;
      arch.memory.latency_cycles = 10;
      arch.memory.bytes_per_cycle = bytes_per_cycle;
    }
    model = std::make_unique<ObjectMemoryModel>(arch, 0);
  }
  Cycle read(const VisitStream& s, Cycle request, BurstConsumer& unit) override { return model->visit(s, request, unit); }
};

VisitStream::Burst triangles(std::uint32_t n) { return {0, n, 48, false}; }
VisitStream::Burst node(std::uint64_t index) { return {index * 32, 1, 32, true}; }

// A ray's work: a flat list of `tests` sphere tests entering the spheres of `visits`, each
// read as `streams` (brute force: one burst of its triangles).
struct TestRay {
  std::vector<VisitWork> visits;
  std::vector<VisitStream> streams;
  PipelineRay ray;
  TestRay(std::uint32_t id, std::uint32_t tests, std::vector<std::pair<std::uint32_t, std::vector<VisitStream::Burst>>> entered = {}) {
    for (const auto& [entry, bursts] : entered) {
      VisitWork v;
      v.entry = entry;
      visits.push_back(v);
      VisitStream s;
      s.bursts = bursts;
      streams.push_back(s);
    }
    ray.id = id;
    ray.sphere_tests = tests;
    ray.visits = visits.data();
    ray.n_visits = static_cast<std::uint32_t>(visits.size());
    ray.streams = streams.data();
  }
};

// Take a ray at max(ready, arrived) and retire it at once (an ideal bus).
Cycle run(PipelinedUnitTiming& p, VisitReader& m, Cycle arrived, const TestRay& r) {
  const Cycle t = std::max(p.ready(), arrived);
  const auto k = p.take(t, arrived, r.ray, m);
  p.retire(k.handle, k.done, k.done);
  return k.done;
}
}  // namespace

TEST_CASE("pipeline: a ray that enters no sphere is answered when its last sphere test is", "[pipeline]") {
  PipelinedUnitTiming p(config(4));
  Memory m;
  CHECK(p.ready() == 0);
  CHECK(run(p, m, 0, TestRay(0, 1)) == 3);  // one test issued at 0, latency 3
  CHECK(p.ready() == 1);                // one ray per cycle from the FIFO
  CHECK(run(p, m, 0, TestRay(1, 5)) == 5 + 3);  // slot 0 is taken: issued 1..5, the last result at 8
  CHECK(p.stats().stage[1].busy == 6);
  CHECK(p.stats().stage[1].ops == 6);
  CHECK(p.stats().jobs == 0);
}

TEST_CASE("pipeline: a job flows sphere -> transform -> triangle; rays finish out of order", "[pipeline]") {
  PipelinedUnitTiming p(config(2));
  Memory m;
  // Ray 0: two sphere tests (0, 1), enters the second (result at 4): transform at 4, result
  // at 6, triangles issued 6..15, the last result at 19.
  CHECK(run(p, m, 0, TestRay(0, 2, {{1, {triangles(10)}}})) == 19);
  // Ray 1 at 2: its test at 2 (result 5), transform at 5 (result 7); the triangle unit's
  // slots 6..15 are taken: triangles 16..20, done 24.
  CHECK(run(p, m, 2, TestRay(1, 1, {{0, {triangles(5)}}})) == 24);
  // Two rays in flight until 19: ray 2, waiting since 3, is taken at 19 (test 19 -> 22,
  // transform 22 -> 24, one triangle at 24, done 28).
  CHECK(p.ready() == 19);
  CHECK(run(p, m, 3, TestRay(2, 1, {{0, {triangles(1)}}})) == 28);
  CHECK(p.stats().slot_wait == 16);  // 3..19 waiting for a ray slot
  // Ray 3 arrives at 20 and enters no sphere: both slots are held until 24 (rays 1 and 2);
  // taken at 24, it is answered at 27, before ray 2 (28).
  CHECK(run(p, m, 20, TestRay(3, 1)) == 27);
  CHECK(p.stats().slot_wait == 16 + 4);
  CHECK(p.stats().stage[4].busy == 16);
  CHECK(p.stats().stage[4].ops == 16);
  CHECK(p.stats().jobs == 3);
}

TEST_CASE("pipeline: a later ray fills the slots an earlier one leaves free, and never delays it", "[pipeline][bvh]") {
  PipelinedUnitTiming p(config(4));
  Memory m;
  // Ray A at 0 walks a BVH: test 0 -> 3, transform 3 -> 5; node at 5 -> 7; its leaf's two
  // triangles at 7, 8 -> 11, 12; the next node waits for them: 12 -> 14; a leaf of one
  // triangle at 14 -> 18.
  CHECK(run(p, m, 0, TestRay(0, 1, {{0, {node(0), triangles(2), node(1), triangles(1)}}})) == 18);
  // Ray B at 1, brute force: test 1 -> 4, transform 4 -> 6, five triangles from 6: 6, then
  // 7 and 8 are A's: 9, 10, 11, 12 (A's 14 is not needed), done 16, before A.
  CHECK(run(p, m, 1, TestRay(1, 1, {{0, {triangles(5)}}})) == 16);
  CHECK(p.stats().stage[3].ops == 2);
  CHECK(p.stats().stage[4].ops == 8);
}

TEST_CASE("pipeline: a tree's tests form one chain, and the walk goes on after the job", "[pipeline][top]") {
  PipelinedUnitTiming p(config(4));
  Memory m;
  TestRay r(0, 0, {{0, {triangles(2)}}});
  r.ray.tree = true;
  r.visits[0].nodes_before = 2;
  r.visits[0].spheres_before = 1;
  r.ray.trailing_nodes = 1;
  // Nodes 0 -> 5, 5 -> 10; the sphere 10 -> 13; transform 13 -> 15; triangles 15, 16 ->
  // 19, 20; the last node waits for the job: 20 -> 25.
  CHECK(run(p, m, 0, r) == 25);
  CHECK(p.stats().stage[0].ops == 3);
  CHECK(p.stats().stage[1].ops == 1);
}

TEST_CASE("pipeline: a ray waits for its data, the units serve the others", "[pipeline][memory]") {
  SECTION("memory slower than the unit: 3 cycles per triangle at 16 bytes per cycle") {
    PipelinedUnitTiming p(config(4));
    Memory m(16);
    // Test 0 -> 3; the transform issues at 3 and requests the burst: streaming from 13,
    // triangles arrive at 16, 19, 22, 25; each issues at its arrival, done 25 + 4.
    CHECK(run(p, m, 0, TestRay(0, 1, {{0, {triangles(4)}}})) == 29);
    CHECK(p.stats().memory_wait == (16 - 5) + 2 + 2 + 2);  // beyond the transform's result, then II
    // A ray taken meanwhile that enters nothing is answered long before.
    CHECK(run(p, m, 1, TestRay(1, 1)) == 4);
  }
  SECTION("memory faster than the unit: 64 bytes per cycle") {
    PipelinedUnitTiming p(config(4));
    Memory m(64);
    // Arrivals 14, 15, 16, 16: issues 14, 15, 16, 17; done 21.
    CHECK(run(p, m, 0, TestRay(0, 1, {{0, {triangles(4)}}})) == 21);
    CHECK(p.stats().memory_wait == 14 - 5);
  }
}

TEST_CASE("pipeline: a ray slot is free only when its answer has left", "[pipeline]") {
  PipelinedUnitTiming p(config(1));
  Memory m;
  const TestRay r(0, 1);
  const auto k = p.take(0, 0, r.ray, m);
  CHECK(k.done == 3);
  CHECK(p.ready() == PipelinedUnitTiming::kNever);  // its answer is still waiting for the bus
  p.retire(k.handle, 3, 5);                         // the bus took it at 5
  CHECK(p.ready() == 5);
  CHECK(p.stats().answer_wait == 2);
  const auto k2 = p.take(5, 1, r.ray, m);  // waited since 1 for the slot
  CHECK(p.stats().slot_wait == 4);
  p.retire(k2.handle, k2.done, k2.done);
  CHECK(p.stats().occupied == 8);  // [0, 5) and [5, 8)
  CHECK_THROWS(p.take(5, 5, r.ray, m));  // before the next take (6)
}

TEST_CASE("pipeline: a full traversal stack spills, an emptied one fills back, each at a cost", "[pipeline][stack]") {
  // Node 0 has children 1 and 6, node 1 children 2 and 5, node 2 children 3 and 4; 3..6 are
  // leaves. A walk that hits everything: 0 (push 6), 1 (push 5), 2 (push 4), 3, then 4, 5, 6
  // popped.
  SceneGeometry<float> g;
  g.nodes.resize(7);
  g.nodes[0].offset = 6;
  g.nodes[1].offset = 5;
  g.nodes[2].offset = 4;
  for (int i = 3; i < 7; ++i) g.nodes[i].count = 1;
  GeometryAddresses<float> at;
  at.node_base = 0;
  at.node_bytes = 32;
  VisitStream v;
  for (std::uint64_t n = 0; n < 7; ++n) v.bursts.push_back(node(n));
  SECTION("one entry in registers: the second and third pushes spill, the last two pops fill") {
    count_stack_overflows(g, at, 1, v);
    CHECK(v.pushes == 3);
    CHECK(v.spills == 2);
    CHECK(v.fills == 2);
    CHECK(v.stack_ops == std::vector<std::uint8_t>{0, 0, 1, 1, 0, 1, 1});
    // Timed: seven dependent box tests (2 cycles each) from the transform's result (2), and
    // four overflows of 10 cycles: 2 + 7 x 2 + 40.
    PipelinedUnitTiming p(config(4));
    Memory m;
    TestRay r(0, 1, {{0, v.bursts}});
    r.streams[0] = v;
    CHECK(run(p, m, 0, r) == 3 + 2 + 7 * 2 + 40);
    CHECK(p.stats().stack_spills == 2);
    CHECK(p.stats().stack_fills == 2);
    CHECK(p.stats().stack_pushes == 3);
  }
  SECTION("three entries: no overflow") {
    count_stack_overflows(g, at, 3, v);
    CHECK(v.pushes == 3);
    CHECK(v.spills + v.fills == 0);
  }
}
