// The pipelined IU's timing (timing/pipeline_timing.h) on small cases computed by hand: each
// stage's issue slots and latency, queues that fill and freeze the stage before them, the
// limit on rays in flight, object-memory bursts.
#include "timing/pipeline_timing.h"

#include <catch2/catch.hpp>

#include <map>
#include <vector>

using namespace oprt;
using namespace oprt::hw;

namespace {
// Sphere unit II 1 latency 3, transform II `t_ii` latency `t_lat`, triangle II 1 latency 4.
PipelineConfig config(int depth, int in_flight, Cycle t_ii = 1, Cycle t_lat = 2) {
  PipelineConfig c;
  c.stage[0] = {1, 3, {}};
  c.stage[1] = {t_ii, t_lat, {}};
  c.stage[2] = {1, 4, {}};
  c.queue_depth = depth;
  c.rays_in_flight = in_flight;
  return c;
}

VisitWork visit(std::uint32_t entry, std::uint32_t triangles) {
  VisitWork v;
  v.entry = entry;
  v.tri_tests = triangles;
  return v;
}

// Take a ray at max(ready, arrived) and retire it at once (an ideal bus).
Cycle run(PipelinedUnitTiming& p, Cycle arrived, std::uint32_t tests, std::vector<VisitWork> visits = {}) {
  const Cycle t = std::max(p.ready(), arrived);
  const auto k = p.take(t, arrived, tests, visits.data(), static_cast<std::uint32_t>(visits.size()));
  p.retire(k.handle, k.done, k.done);
  return k.done;
}

// Records the waveform's last report per (signal, time).
struct Recorder : PipelineTrace {
  std::map<std::pair<int, Cycle>, int> state;
  std::map<std::pair<int, Cycle>, int> queue_delta;
  void stage(PipeStage s, Cycle t, StageState st) override { state[{static_cast<int>(s), t}] = static_cast<int>(st); }
  void queue(int q, Cycle t, int d) override { queue_delta[{q, t}] += d; }
  void in_flight(Cycle, int) override {}
  // The state of stage s at time t: the last report at or before t.
  int at(PipeStage s, Cycle t) const {
    int v = 0;
    for (const auto& [k, st] : state)
      if (k.first == static_cast<int>(s) && k.second <= t) v = st;
    return v;
  }
};
}  // namespace

TEST_CASE("pipeline: a ray that enters no sphere is answered when its last sphere test is", "[pipeline]") {
  PipelinedUnitTiming p(config(4, 4));
  CHECK(p.ready() == 0);
  CHECK(run(p, 0, 1) == 3);       // one test issued at 0, latency 3
  CHECK(p.ready() == 1);          // the next issue slot
  CHECK(run(p, 0, 5) == 1 + 4 + 3);  // issued 1..5, the last result at 8
  CHECK(p.stats().stage[0].busy == 6);
  CHECK(p.stats().jobs == 0);
}

TEST_CASE("pipeline: a job flows sphere -> transform -> triangle; rays finish out of order", "[pipeline]") {
  PipelinedUnitTiming p(config(1, 2));
  // Ray 0: two sphere tests, enters the second (issued at 1, result at 4): transform at 4,
  // result at 6, triangles issued 6..15, the last result at 19.
  CHECK(run(p, 0, 2, {visit(1, 10)}) == 19);
  // Ray 1 at 2: its test's result at 5 enters the transform queue (the job before left it
  // at 4); transform 5 -> 7; the triangle unit is busy until 16: triangles 16..20, done 24.
  CHECK(run(p, 2, 1, {visit(0, 5)}) == 24);
  // Two rays in flight until 19: ray 2, waiting since 3, is taken at 19 (test 19 -> 22,
  // transform 22 -> 24, one triangle at 24, done 28).
  CHECK(p.ready() == 19);
  CHECK(run(p, 3, 1, {visit(0, 1)}) == 28);
  // Sphere unit stalled 3..19 waiting for a ray slot.
  CHECK(p.stats().stage[0].full == 16);
  // Ray 3 arrives at 20 and enters no sphere: both slots are held until 24 (rays 1 and 2);
  // taken at 24, it is answered at 27, before ray 2 (28).
  CHECK(run(p, 20, 1) == 27);
  CHECK(p.stats().stage[0].full == 16 + 4);
  CHECK(p.stats().stage[2].busy == 16);
  CHECK(p.stats().triangles == 16);
  CHECK(p.stats().jobs == 3);
}

TEST_CASE("pipeline: a full triangle queue freezes the transform unit", "[pipeline]") {
  PipelinedUnitTiming p(config(1, 8));
  // Three tests, each entering a sphere with 10 triangles. Job 0: result 3, transform 3 -> 5,
  // triangles 5..14 (done 18). Job 1: result 4, transform 4 -> 6, waits in the triangle
  // queue until 15: triangles 15..24 (done 28). Job 2: result 5, transform 5 -> 7, but the
  // queue holds job 1 until 15: the transform unit freezes 7..15; triangles 25..34, done 38.
  CHECK(run(p, 0, 3, {visit(0, 10), visit(1, 10), visit(2, 10)}) == 38);
  CHECK(p.stats().stage[1].full == 8);
  CHECK(p.stats().stage[2].busy == 30);
  // The transform unit's clock stopped 7..15: a job it issues at 6 (virtual) is unaffected,
  // its result (virtual 8) comes 8 cycles late, at 16, and waits for room until 25 (job 2
  // leaves the queue then): a second freeze, 9 cycles. Triangle at 35, done 39.
  CHECK(run(p, 3, 1, {visit(0, 1)}) == 39);
  CHECK(p.stats().stage[1].full == 17);
  CHECK(p.stats().peak_queue[1] == 1);
}

TEST_CASE("pipeline: a full transform queue freezes the sphere unit, and its clock", "[pipeline]") {
  Recorder trace;
  PipelinedUnitTiming p(config(1, 8, /*transform II*/ 5, /*latency*/ 6), &trace);
  // Tests issued 0, 1, 2 with results at 3, 4, 5, each entering a sphere (1 triangle). The
  // transform unit takes job 0 at 3, job 1 at 8 (II 5); job 2's result at 5 finds job 1
  // still queued until 8: the sphere unit freezes 5..8. Job 2 transforms at 13 -> 19,
  // its triangle at 19, done 23.
  CHECK(run(p, 0, 3, {visit(0, 1), visit(1, 1), visit(2, 1)}) == 23);
  CHECK(p.stats().stage[0].full == 3);
  CHECK(p.ready() == 3);  // issue slot 3 comes before the freeze (at the unit's cycle 5)
  // A ray issued at 3 has its result at the unit's cycle 6, which the freeze moved to 9.
  CHECK(run(p, 3, 1) == 9);
  // A ray arriving at 6, inside the freeze, issues when it ends, at 8 (the unit's cycle 5).
  CHECK(run(p, 6, 1) == 11);
  // The waveform: issuing at 0..2, frozen 5..7 (cycles 3 and 4 busy with the second ray's
  // test at 3 and idle at 4), busy at 8 again.
  CHECK(trace.at(PipeStage::sphere, 2) == static_cast<int>(StageState::busy));
  CHECK(trace.at(PipeStage::sphere, 4) == static_cast<int>(StageState::waiting));
  CHECK(trace.at(PipeStage::sphere, 6) == static_cast<int>(StageState::full));
  CHECK(trace.at(PipeStage::sphere, 8) == static_cast<int>(StageState::busy));
  CHECK(trace.at(PipeStage::sphere, 9) == static_cast<int>(StageState::waiting));
}

TEST_CASE("pipeline: triangles wait for object memory, one burst at a time", "[pipeline][memory]") {
  PipelineConfig c = config(4, 4);
  c.memory_latency = true;
  c.memory_latency_cycles = 10;
  c.triangle_bytes = 48;
  SECTION("memory slower than the unit: 3 cycles per triangle at 16 bytes per cycle") {
    c.memory_bytes_per_cycle = 16;
    PipelinedUnitTiming p(c);
    // Test 0 -> 3, transform at 3 requests the burst: streaming from 13, triangles arrive
    // at 16, 19, 22, 25; the unit could start at 5: it issues at each arrival, done 25 + 4.
    CHECK(run(p, 0, 1, {visit(0, 4)}) == 29);
    CHECK(p.stats().stage[2].memory == 25 - (5 + 3));
  }
  SECTION("memory faster than the unit: 64 bytes per cycle") {
    c.memory_bytes_per_cycle = 64;
    PipelinedUnitTiming p(c);
    // Arrivals 14, 15, 16, 16: issues 14, 15, 16, 17; done 21.
    CHECK(run(p, 0, 1, {visit(0, 4)}) == 21);
    CHECK(p.stats().stage[2].memory == 17 - 8);
  }
}

TEST_CASE("pipeline: a ray slot is free only when its answer has left", "[pipeline]") {
  PipelinedUnitTiming p(config(4, 1));
  const auto k = p.take(0, 0, 1, nullptr, 0);
  CHECK(k.done == 3);
  CHECK(p.ready() == PipelinedUnitTiming::kNever);  // its answer is still waiting for the bus
  p.retire(k.handle, 3, 5);                         // the bus took it at 5
  CHECK(p.ready() == 5);
  CHECK(p.stats().answer_wait == 2);
  const auto k2 = p.take(5, 1, 1, nullptr, 0);  // waited since 1 for the slot
  CHECK(p.stats().stage[0].full == 4);
  p.retire(k2.handle, k2.done, k2.done);
  CHECK(p.stats().occupied == 8);  // [0, 5) and [5, 8)
  CHECK_THROWS(p.take(5, 5, 1, nullptr, 0));  // before the next issue slot (6)
}
