// The timing of a pipelined intersection unit (`"iu": {"model": "pipelined"}`): the paper's
// future work, separate units for each operation, with several rays in flight. Plain C++,
// the one place this is decided: the SystemC unit (hw/pipelined_unit.cpp), `lt` and the
// analytic level all call it, ray by ray, in the order the unit takes its rays.
//
//   ray FIFO -> ray store (rays_in_flight slots, each with its traversal stack)
//                 |  each ray walks its own program of operations, one after the other;
//                 v  each operation waits for the unit that runs it:
//   node unit (--top bvh) | sphere unit | transform unit | box unit (--accel bvh) | triangle unit
//                 |  object memory (object_memory_model.h: on-chip, or a cache) feeds the box
//                 v  and triangle units; a ray waits for its data, the units serve other rays
//   answer -> bus
//
// Units. Each runs its operation graph (cycle_schedule.h) on its own adders and multipliers,
// modulo scheduled: it accepts a new operation every II cycles and produces its result L
// cycles after issue. The node unit tests nodes of the unit's tree over its spheres, the
// sphere unit sphere tests, the transform unit carries a ray into a sphere's frame (and with
// --accel bvh forms its reciprocal direction too: transform_box_setup_graph), the box unit
// tests BVH nodes, the triangle unit triangles.
//
// A ray's program, from the functional trace's record of its work (functional_frame.h):
//  - flat list: the sphere tests of its registers, one after the other (independent: each
//    issues at the first free slot); a shadow ray's up to its occluder's, as the trace
//    records them. Tree (--top bvh): its node and sphere tests form a chain, each issued
//    when the one before has its result, and after an entered sphere the walk goes on only
//    when that sphere's job is done (which nodes it skips depends on the nearest hit so
//    far, or on whether a shadow ray is already occluded). The trace keeps, per entered
//    sphere, how many node and sphere tests came before it: they are run nodes first.
//  - per entered sphere a job, one at a time per ray (a ray has one local-frame register
//    set): the transform, when the sphere test's result (or the job before) is there; then
//    the visit's reads from object memory, the first requested when the transform issues:
//    brute force, the tested triangles, each issued when the transform's result and its
//    data are there; with a BVH the walk, each node's box test issued when its data and the
//    test before are there (the next node depends on it), each leaf's triangles likewise,
//    and the next node after a leaf when the leaf's last result is there (the walk's limit,
//    the nearest hit so far, depends on it).
//  - the ray's answer is ready when its last operation's result is; rays finish out of
//    order, and a ray's slot is free when its answer has left (retire()).
// Arbitration: a unit issues the oldest ray's operation first. The whole program of a ray is
// placed when the unit takes it, each operation in the first free issue slot at or after
// the time it is ready (a calendar per unit, calendar.h): a ray taken later fills the slots
// the rays before it left free, and never delays them. Its timing depends only on the rays
// taken before it, which is what lets every level compute it the same way.
//
// The traversal stack. Each ray slot holds a stack of `stack_depth` entries (node indices,
// 4 bytes) in the ray store. A push onto a full stack spills its bottom entry to object
// memory, a pop from an empty stack whose entries were spilled fills one back; either costs
// that ray `stack_overflow_cycles` (an access of one entry) before its next node. Spills and
// fills are counted; the ray store's bytes are area (cost_model.h).
//
// Memory: a ray that waits for data holds its slot and waits alone (miss under miss): the
// units serve the other rays, and the object memory keeps up to misses_outstanding misses
// in flight (MissWindow). Time in cycles of the architecture's clock.
#pragma once

#include "arch/arch.h"
#include "arch/cycle_schedule.h"
#include "timing/calendar.h"
#include "timing/cycle.h"
#include "ref/functional_frame.h"
#include "timing/object_memory_model.h"
#include "timing/visit_stream.h"

#include <cstdint>
#include <deque>
#include <set>
#include <vector>

namespace oprt::timing {

enum class PipeStage : std::uint8_t { node = 0, sphere = 1, transform = 2, box = 3, triangle = 4 };
constexpr int kPipeStages = 5;
const char* to_string(PipeStage s);

struct StageTiming {
  bool used = false;  // the node unit only with --top bvh, the box unit only with --accel bvh
  Cycle ii = 1, latency = 1;
  FpUnits units;
};

struct PipelineConfig {
  StageTiming stage[kPipeStages];
  int rays_in_flight = 16;
  int stack_depth = 16;
  Cycle stack_overflow_cycles = 10;
};

// The schedules the pipelined IU runs for the architecture: per used unit its graph,
// modulo scheduled on its FP units (IuConfig's counts; 0 = enough for II 1).
struct PipelineSchedules {
  bool used[kPipeStages] = {};
  Schedule stage[kPipeStages];
};
PipelineSchedules pipeline_schedules(const Arch& a);
PipelineConfig pipeline_config(const Arch& a);
FpUnits stage_units(const Arch& a, PipeStage s, const OpGraph& g);

struct StageCycles {
  std::uint64_t ops = 0;   // operations issued
  std::uint64_t busy = 0;  // issue slots taken: ops x II
};

struct PipelineStats {
  StageCycles stage[kPipeStages];
  std::uint64_t occupied = 0;     // cycles in which the unit held at least one ray
  std::uint64_t answer_wait = 0;  // cycles answers waited for the bus (ray-cycles)
  std::uint64_t slot_wait = 0;    // cycles a ray waited in the FIFO for a free ray slot
  std::uint64_t memory_wait = 0;  // ray-cycles waiting for object memory beyond the operation before
  std::uint64_t jobs = 0;         // (ray, entered sphere)
  std::uint64_t stack_pushes = 0, stack_spills = 0, stack_fills = 0;
  std::uint32_t peak_in_flight = 0;
};

// Where a pipelined unit reports its waveform and timeline (times in cycles). Reports come
// in take order, not time order (a later ray fills earlier slots): every signal is a sum of
// changes, which the writer adds up in time order.
class PipelineTrace {
 public:
  virtual ~PipelineTrace() = default;
  virtual void issue(PipeStage s, Cycle start, Cycle end, std::uint32_t ray) = 0;  // an issue slot
  virtual void waiting(PipeStage s, Cycle from, Cycle to) = 0;  // an operation ready, not yet issued
  virtual void memory(Cycle from, Cycle to) = 0;                // a ray waiting for its data
  virtual void in_flight(Cycle t, int delta) = 0;
};

// How the unit reads a visit's bursts (object_memory_model.h): the SystemC unit through its
// memory socket, the analytic level from its model directly.
class VisitReader {
 public:
  virtual ~VisitReader() = default;
  virtual Cycle read(const VisitStream& s, Cycle request, BurstConsumer& unit) = 0;
};

// One ray's work in the unit: the trace's record (functional_frame.h) and the reads of each
// entered sphere (streams[i] for visits[i], walked again where the order matters).
struct PipelineRay {
  std::uint32_t id = 0;
  bool tree = false;                 // --top bvh
  std::uint32_t sphere_tests = 0;    // flat: the tests in register order (the entries up to this)
  const VisitWork* visits = nullptr;
  std::uint32_t n_visits = 0;
  std::uint32_t trailing_nodes = 0, trailing_spheres = 0;  // tree: tests after the last entered sphere
  const VisitStream* streams = nullptr;
};

class PipelinedUnitTiming {
 public:
  static constexpr Cycle kNever = INT64_MAX;
  using Handle = std::uint64_t;

  explicit PipelinedUnitTiming(const PipelineConfig& c, PipelineTrace* trace = nullptr);

  // The earliest time the unit can take a new ray: one per cycle, once a ray slot is free.
  // kNever while every slot holds a ray whose answer has not yet left.
  Cycle ready() const;
  struct Taken {
    Handle handle;
    Cycle done;  // the answer is ready
  };
  // Take a ray at time t >= ready() (it was in the ray FIFO from `arrived`) and place its
  // program; its visits' reads go through `memory`.
  Taken take(Cycle t, Cycle arrived, const PipelineRay& ray, VisitReader& memory);
  // The ray's answer left the unit at time t (>= its done time).
  void retire(Handle h, Cycle done, Cycle t);

  // The earliest time the unit may still report to its PipelineTrace.
  Cycle trace_floor() const { return next_take_; }
  const PipelineStats& stats() const { return stats_; }
  void reset_stats();
  const PipelineConfig& config() const { return c_; }

 private:
  class Job;
  // Operation of stage s, ready at `ready`: the first free issue slot; returns its result.
  Cycle run(PipeStage s, Cycle ready, std::uint32_t ray, Cycle* start_out = nullptr);
  Cycle job(const PipelineRay& ray, std::uint32_t i, Cycle ready, VisitReader& memory);

  PipelineConfig c_;
  PipelineTrace* trace_;
  Calendar<Cycle> slots_[kPipeStages];
  Cycle next_take_ = 0;
  // Rays in flight: slots held by rays whose answer has not left, and the times at which
  // the others' answers leave (later than the last take).
  std::uint64_t unretired_ = 0;
  std::multiset<Cycle> leaving_;
  // Occupied cycles: the union of [take, retire) in take order (retire times come in any order).
  struct Span {
    Cycle start, end;
  };
  std::deque<Span> spans_;
  Handle first_span_ = 0;
  Cycle covered_until_ = 0;
  PipelineStats stats_;
};

// A pipelined unit's cycles as a serial unit's are reported: each unit's issue cycles, and
// the rays' waits for object memory and for the bus. They may add up to more than the time
// it held rays (PipelineStats::occupied), since its units work side by side.
inline UnitCycles pipelined_cycles(const PipelineStats& p) {
  UnitCycles c;
  c.node = p.stage[0].busy;
  c.sphere = p.stage[1].busy;
  c.transform = p.stage[2].busy;
  c.box = p.stage[3].busy;
  c.primitive = p.stage[4].busy;
  c.stall = p.memory_wait + p.answer_wait;
  return c;
}

// The stack's spills and fills of a BVH walk, before each burst (VisitStream::stack_ops):
// from the node indices the walk visited (a node that is a child of the one before was
// reached by descending, which pushed its sibling; any other node was popped).
template <typename T>
void count_stack_overflows(const SceneGeometry<T>& g, const GeometryAddresses<T>& at, int depth, VisitStream& v);

}  // namespace oprt::timing

namespace oprt::timing {

// A unit's work on a ray as its pipeline runs it: the trace's record, and each entered
// sphere's reads in the order the unit makes them (brute force: one burst of the tested
// triangles; with a BVH the walk again, for its order and its stack).
template <typename T>
class PipelineRayBuilder {
 public:
  PipelineRayBuilder(const SceneGeometry<T>& g, const Arch& a) : g_(g), a_(a), at_(g) {}
  const PipelineRay& build(const FunctionalFrame<T>& f, std::uint32_t u, const UnitRayWork* w, std::uint32_t id,
                           const IuRegisters<T>& regs) {
    const auto rv = f.ray_visits(w, u);
    ray_ = PipelineRay{};
    ray_.id = id;
    ray_.tree = f.unit_top[u] != 0;
    ray_.visits = rv.visits.first;
    ray_.n_visits = rv.visits.size();
    if (!ray_.tree) {
      ray_.sphere_tests = rv.sphere_tests;
    } else if (!w) {
      ray_.trailing_nodes = 1;  // the root, missed
    } else {
      const std::uint32_t i = f.units[u].index(w);
      std::uint32_t nodes = 0, spheres = 0;
      for (const VisitWork& v : rv.visits) nodes += v.nodes_before, spheres += v.spheres_before;
      ray_.trailing_nodes = f.node_tests_of(u, i) - nodes;
      ray_.trailing_spheres = f.sphere_tests_of(u, i) - spheres;
    }
    if (streams_.size() < ray_.n_visits) streams_.resize(ray_.n_visits);
    const RayRecord<T>& r = f.rays[id];
    for (std::uint32_t k = 0; k < ray_.n_visits; ++k) {
      const VisitWork& v = ray_.visits[k];
      VisitStream& s = streams_[k];
      if (g_.has_bvh()) {
        const WorkCounts again = visit_stream(g_, regs, r.ray, r.kind, v.entry, at_, s);
        if (again.tri_tests() != v.tri_tests || again.box_tests != v.box_tests)
          throw std::logic_error("a visit walked again for its order differs from the functional trace");
        count_stack_overflows(g_, at_, a_.iu.stack_depth, s);
      } else {
        s.bursts.clear();
        s.stack_ops.clear();
        s.pushes = s.spills = s.fills = 0;
        const std::uint32_t sphere = regs.sphere[v.entry];
        s.sphere = sphere;
        if (v.tri_tests)
          s.bursts.push_back({at_.triangle(g_.first[sphere]), v.tri_tests, static_cast<std::uint32_t>(at_.triangle_bytes), false});
      }
    }
    ray_.streams = streams_.data();
    return ray_;
  }

 private:
  const SceneGeometry<T>& g_;
  const Arch& a_;
  const GeometryAddresses<T> at_;
  std::vector<VisitStream> streams_;
  PipelineRay ray_;
};

}  // namespace oprt::timing
