// IntersectionUnit: one adder, one multiplier and a register file (the paper's IU). It pops
// rays from its FIFO, tests each against its spheres (registers written by the GPP each
// frame), carries the ray into a sphere's local frame on a hit and tests that sphere's
// triangles streamed from its object memory, then answers the GPP over the bus: the nearest
// hit of a primary ray, or whether a shadow ray is occluded (it stops at the first
// occluder).
//
// The work itself was traced before the frame's timing (functional_frame.h: the same
// traversal, traverse.h's); the unit looks up its record for the ray it pops, reads the
// spheres it entered from its object memory, charges the cycles (unit_cycles.h) and sends
// the recorded answer. The cycles of a ray are known when it starts, so the unit waits them
// out in one step (phases are only reported to the VCD, with their times): one simulation
// event per ray at most, none while idle, and none at all per ray when nothing can observe
// the unit's intermediate times (local_clock.h, `ahead`).
//
// When its spheres do not fit its object memory, the memory is a cache (cache.h): the unit
// then works through a ray visit by visit, sends each visit's reads with their addresses
// (walked again, visit_stream.h) and lets the memory time them line by line.
//
// With `"iu": {"model": "pipelined"}` the unit is a pipeline of a sphere, a transform and
// a triangle unit with several rays in flight; its timing is timing/pipeline_timing.h's, and
// its answers leave out of ray order, each at its own time. Where nothing can observe the
// unit (`ahead`), it takes each ray as soon as the pipeline can. Otherwise (a bounded FIFO,
// a shared bus) it pops each ray at the simulated time the pipeline takes it. On an ideal
// bus an answer takes no time and meets no other transfer: it is sent at once, annotated
// with its time, and the GPP acts on it only then (gpp.cpp). On a shared bus a second
// process sends each answer when it is ready, in time order, and frees its ray slot when
// the bus has taken it.
#pragma once

#include "timing/functional_frame.h"
#include "hw/local_clock.h"
#include "hw/payloads.h"
#include "timing/pipeline_timing.h"
#include "hw/ray_fifo.h"
#include "timing/unit_cycles.h"
#include "trace/timeline.h"
#include "trace/vcd_writer.h"
#include "timing/visit_stream.h"
#include "hw/watchdog.h"

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

#include <memory>
#include <optional>
#include <queue>

namespace oprt::hw {

enum class UnitState : std::uint8_t { idle = 0, sphere = 1, transform = 2, primitive = 3, stall = 4, box = 5, node = 6 };

// What the unit measured in the frame. Its busy cycles by activity are the functional
// trace's (FunctionalFrame::unit_cycles); `charged` is what it waited out for them, which must
// agree, and the bus is the stall only the timed model knows.
struct UnitStats {
  std::uint64_t charged = 0;    // busy and memory stall, summed ray by ray
  std::uint64_t bus_stall = 0;  // waiting for the shared bus to take its answers
  // Through an object memory that is a cache (--sram): its stall replaces the trace's, which
  // is on-chip memory's.
  std::uint64_t cache_stall = 0;
  std::optional<PipelineStats> pipeline;  // a pipelined unit's stages (its cycles are theirs)
  std::uint64_t rays[kRayKinds] = {};
};

template <typename T>
class IntersectionUnit : public sc_core::sc_module, public Waiter {
 public:
  tlm_utils::simple_target_socket<IntersectionUnit> cfg;    // configuration registers (from the bus)
  tlm_utils::simple_initiator_socket<IntersectionUnit> bus;  // answers to the GPP
  tlm_utils::simple_initiator_socket<IntersectionUnit> mem;  // its object memory
  sc_core::sc_port<RayFifoIf> fifo;

  SC_HAS_PROCESS(IntersectionUnit);
  IntersectionUnit(const sc_core::sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
                   const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline = nullptr);
  ~IntersectionUnit() override;

  int id() const { return id_; }
  const IuRegisters<T>& registers() const { return regs_; }
  UnitStats& stats();
  // The earliest time the unit may still report to the waveform (a pipelined unit reports
  // its stages' stalls once it knows them, behind simulation time); no limit for a serial one.
  sc_core::sc_time trace_floor() const { return pipe_ ? time_of(pipe_->trace_floor()) : sc_core::sc_max_time(); }
  void reset_stats();
  std::string waiting_for() const override;

 private:
  void run();
  void cfg_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void read_memory(std::uint32_t sphere, std::uint64_t bytes);
  std::uint64_t trace_through_cache(std::uint32_t ray, const RayRecord<T>& r, const UnitRayWork& w);
  void advance_tracing(std::uint32_t ray, UnitState s, std::uint64_t cycles);
  void trace_state(UnitState s, const sc_core::sc_time& at);
  void trace_phases(std::uint32_t ray, const UnitRayWork* w, sc_core::sc_time at);
  void send_answer(std::uint32_t ray, const UnitRayWork* w, sc_core::sc_time& delay);
  // Pipelined: the intake (pops rays) and, unless it runs ahead, the write-back (answers).
  void run_pipelined();
  void write_back();
  void take(const RayEntry& e, Cycle t);
  sc_core::sc_time time_of(Cycle c) const { return sc_core::sc_time::from_value(cycle_.value() * static_cast<std::uint64_t>(c)); }
  Cycle cycle_of(const sc_core::sc_time& t) const { return static_cast<Cycle>((t.value() + cycle_.value() / 2) / cycle_.value()); }

  const int id_;
  const Arch& arch_;
  const SceneGeometry<T>& geom_;
  const FunctionalFrame<T>& frame_;
  const sc_core::sc_time cycle_;
  const std::uint32_t triangle_bytes_;
  // How far a unit running ahead may lead simulation time while the trace writer is over
  // its budget: the units behind keep going (no wait) until they lead by as much.
  static constexpr std::uint64_t kTraceLeadCycles = std::uint64_t{1} << 13;
  const sc_core::sc_time trace_lead_;
  IuRegisters<T> regs_;
  UnitStats stats_;
  LocalClock clock_;
  const bool sync_on_bus_;
  // Its object memory is a cache this frame (ConfigPacket), and what timing through it needs.
  bool cached_ = false;
  const bool sync_misses_;  // the memory waits until each miss is due (shared DRAM channel or bus)
  const GeometryAddresses<T> addresses_;
  VisitStream stream_;
  tlm::tlm_generic_payload answer_, read_;
  VcdWriter* vcd_;  // null when its state is not traced
  VcdWriter* writer_;  // the waveform writer, whatever it traces (its budget, vcd_writer.h)
  int vcd_state_ = -1;
  static constexpr UnitState kStateUnknown = static_cast<UnitState>(0xff);
  UnitState traced_state_ = UnitState::idle;  // the last state reported to vcd_ (by the unit)
  TimelineWriter* timeline_;  // null when not traced
  int track_ = -1;
  // For the watchdog: what the process is doing (plain stores, no events).
  enum class Activity : std::uint8_t { waiting_for_ray, tracing, answering, waiting_for_slot } activity_ =
      Activity::waiting_for_ray;
  std::uint32_t ray_ = 0;

  // Pipelined unit.
  struct Answer {
    Cycle done;
    std::uint32_t ray;
    PipelinedUnitTiming::Handle handle;
    bool operator>(const Answer& o) const { return done != o.done ? done > o.done : ray > o.ray; }
  };
  class Trace;
  std::unique_ptr<Trace> pipe_trace_;
  std::unique_ptr<PipelinedUnitTiming> pipe_;
  std::priority_queue<Answer, std::vector<Answer>, std::greater<Answer>> answers_;
  sc_core::sc_event answer_queued_, slot_freed_;
};

extern template class IntersectionUnit<float>;
extern template class IntersectionUnit<double>;

}  // namespace oprt::hw
