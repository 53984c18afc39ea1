// The timing of a pipelined intersection unit (`"iu": {"model": "pipelined"}`): a sphere
// unit, a transform unit and a triangle unit, joined by queues, with several rays in
// flight. Plain C++, shared by the SystemC unit (intersection_unit.cpp) and the analytic
// level: the timing of a ray is a function of when the unit takes it and of the functional
// record of its work (functional_frame.h: the spheres it tested, the spheres it entered and
// the triangles it tested in each), so it is computed when the ray is taken.
//
//   ray FIFO -> sphere unit -> queue -> transform unit -> queue -> triangle unit -> answer
//
// - The sphere unit takes a ray when it has a free issue slot and the unit has fewer than
//   `rays_in_flight` rays in flight, and issues one sphere test every II_s cycles, in
//   register order. A test that enters its sphere puts a job (ray, sphere) in the transform
//   queue when its result is ready, L_s cycles after it issued.
// - The transform unit issues one job every II_t cycles, in queue order; its result, L_t
//   later, enters the triangle queue.
// - The triangle unit takes one job at a time, in queue order, and issues the sphere's
//   triangles one every II_tri cycles (brute force: every triangle the functional record
//   says the ray tested). A job's last result is ready L_tri cycles after its last issue.
//   An early exit does not shorten the pipeline: every triangle takes its issue slot.
// - A ray's answer is ready when its last sphere test's result and its last job are; rays
//   finish out of order (a ray that enters no sphere overtakes one whose triangles are
//   still being tested). Its slot among the rays in flight is free when its answer has
//   left (retire(): at once on an ideal bus, after its transfer on a shared one).
// A queue that is full freezes the unit that feeds it: the unit's pipeline stops, every op
// in it waits, and it issues nothing until the queue has room (valid/ready flow control
// with a stall of the whole unit). Time in a frozen unit is its `full` stall.
//
// With `memory.model` `latency`, the triangles of a job come from object memory in one
// burst, requested when the transform unit starts the job (its transform hides latency, as
// in the serial unit) and served one burst at a time: item j of a burst that starts
// streaming at b arrives at b + latency + ceil((j + 1) bytes / bytes_per_cycle); a burst
// starts streaming when the previous one has been delivered. The triangle unit waits for
// each item: that wait is its `memory` stall.
//
// Each II and L comes from the unit's operation graph, modulo scheduled on its adders and
// multipliers (cycle_schedule.h). Times are in cycles of the architecture's clock.
#pragma once

#include "arch/arch.h"
#include "arch/cycle_schedule.h"
#include "timing/functional_frame.h"

#include <cstdint>
#include <deque>
#include <set>
#include <string>
#include <vector>

namespace oprt::hw {

using Cycle = std::int64_t;

enum class PipeStage : std::uint8_t { sphere = 0, transform = 1, triangle = 2 };
constexpr int kPipeStages = 3;
const char* to_string(PipeStage s);
// A stage's state in the VCD: waiting (nothing to issue), busy (issuing), full (frozen by
// its output queue), memory (the triangle unit waiting for object memory).
enum class StageState : std::uint8_t { waiting = 0, busy = 1, full = 2, memory = 3 };

struct StageTiming {
  Cycle ii = 1, latency = 1;
  FpUnits units;
};

struct PipelineConfig {
  StageTiming stage[kPipeStages];
  int queue_depth = 4;  // 0 = unbounded
  int rays_in_flight = 16;
  bool memory_latency = false;
  Cycle memory_latency_cycles = 0, memory_bytes_per_cycle = 1, triangle_bytes = 48;
};

// The three schedules the pipelined IU runs for the architecture's kernel (the stable
// sphere test, the kernel's transform and triangle test), on its units.
struct PipelineSchedules {
  Schedule stage[kPipeStages];
};
PipelineSchedules pipeline_schedules(const Arch& a);
PipelineConfig pipeline_config(const Arch& a, std::uint32_t triangle_bytes);
// The units a stage runs its graph on (IuConfig's counts; 0 = enough for II 1).
FpUnits stage_units(const Arch& a, PipeStage s, const OpGraph& g);

// Cycles of one stage in a frame. Idle and starved (its input queue empty while the unit
// holds rays) follow from the unit's occupied cycles at the frame's end.
struct StageCycles {
  std::uint64_t busy = 0;    // issuing: II per op instance
  std::uint64_t full = 0;    // frozen: its output queue was full (sphere unit: also no free ray slot)
  std::uint64_t memory = 0;  // triangle unit: waiting for object memory
};

struct PipelineStats {
  StageCycles stage[kPipeStages];
  std::uint64_t occupied = 0;     // cycles in which the unit held at least one ray
  std::uint64_t answer_wait = 0;  // cycles answers waited for the bus
  std::uint64_t jobs = 0;         // (ray, sphere) jobs: each one push and one pop in each queue
  std::uint64_t triangles = 0;    // triangle tests issued
  std::uint32_t peak_queue[2] = {};  // transform queue, triangle queue: most entries at once
  std::uint32_t peak_in_flight = 0;
};

// Where a pipelined unit reports its waveform (times in cycles). Several reports for one
// signal at one time: the last one holds.
class PipelineTrace {
 public:
  virtual ~PipelineTrace() = default;
  virtual void stage(PipeStage s, Cycle t, StageState state) = 0;
  virtual void queue(int q, Cycle t, int delta) = 0;  // 0: transform queue, 1: triangle queue
  virtual void in_flight(Cycle t, int delta) = 0;
};

class PipelinedUnitTiming {
 public:
  static constexpr Cycle kNever = INT64_MAX;
  using Handle = std::uint64_t;

  explicit PipelinedUnitTiming(const PipelineConfig& c, PipelineTrace* trace = nullptr);

  // The earliest time the sphere unit can take a new ray: its next issue slot, once a ray
  // slot is free. kNever while every slot holds a ray whose answer has not yet left.
  Cycle ready() const;
  struct Taken {
    Handle handle;
    Cycle done;  // the answer is ready
  };
  // Take a ray at time t >= ready() (it was in the ray FIFO from `arrived`) that tested
  // `sphere_tests` spheres and entered `visits` of them (each with its triangle tests).
  Taken take(Cycle t, Cycle arrived, std::uint32_t sphere_tests, const VisitWork* visits, std::uint32_t n_visits);
  // The ray's answer left the unit at time t (>= its done time).
  void retire(Handle h, Cycle done, Cycle t);

  // The earliest time the unit may still report to its PipelineTrace (the waveform writer
  // must not write past it).
  Cycle trace_floor() const;
  const PipelineStats& stats() const { return stats_; }
  void reset_stats();
  const PipelineConfig& config() const { return c_; }

 private:
  // A stage whose pipeline freezes while its output queue is full. Its own ("virtual")
  // time stops while frozen: global time = virtual time + the freezes up to then.
  struct Stage {
    struct Freeze {
      Cycle at, total;  // virtual instant; cumulative freeze after it
    };
    std::deque<Freeze> freezes;
    Cycle base = 0;     // cumulative freeze of those forgotten
    Cycle next_v = 0;   // virtual time of the next free issue slot
    Cycle global(Cycle v) const;      // v + every freeze at instants <= v
    Cycle virtual_of(Cycle g) const;  // the earliest virtual time at or after global g
    void freeze(Cycle at, Cycle d);
    void forget_before(Cycle v);
    // Global intervals [start, end) of recent freezes (for the waveform).
    std::deque<std::pair<Cycle, Cycle>> recent;
  };
  // A queue between stages: its entries' pop times, for room and occupancy.
  struct Queue {
    std::deque<Cycle> pops;     // pop times of the last `depth` entries (room)
    std::deque<Cycle> pending;  // pop times after the latest push (occupancy in time order)
  };
  // When an entry whose result is ready at global g may enter q: when the entry `depth`
  // places earlier has left.
  Cycle room(const Queue& q, Cycle g) const;
  void push(Queue& q, int index, Cycle at, Cycle pop);
  // Stage s's result at virtual instant v needs q's room: freezes s if it must wait;
  // returns the global time the result enters q.
  Cycle enter(Stage& s, PipeStage which, Cycle v, const Queue& q);
  void trace_window(Stage& s, PipeStage which, Cycle v0, Cycle v_end);
  void job(Cycle entered_transform_queue, std::uint32_t triangles, Cycle& done);

  PipelineConfig c_;
  PipelineTrace* trace_;
  Stage sphere_, transform_;
  Queue q_[2];
  Cycle triangle_free_ = 0, memory_free_ = 0;
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

// A pipelined unit's cycles as a serial unit's are reported: each stage's issue cycles, and
// its stalls (object memory, answers waiting for the bus). They may add up to more than the
// time it held rays (PipelineStats::occupied), since the stages work side by side.
inline UnitCycles pipelined_cycles(const PipelineStats& p) {
  UnitCycles c;
  c.sphere = p.stage[0].busy;
  c.transform = p.stage[1].busy;
  c.primitive = p.stage[2].busy;
  c.stall = p.stage[2].memory + p.answer_wait;
  return c;
}

}  // namespace oprt::hw
