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
// With `"iu": {"model": "pipelined"}` the unit is a pipeline of a sphere, a transform and
// a triangle unit with several rays in flight; its timing is hw/pipeline_timing.h's, and
// its answers leave out of ray order, each at its own time. Where nothing can observe the
// unit (`ahead`), it takes each ray as soon as the pipeline can. Otherwise (a bounded FIFO,
// a shared bus) it pops each ray at the simulated time the pipeline takes it. On an ideal
// bus an answer takes no time and meets no other transfer: it is sent at once, annotated
// with its time, and the GPP acts on it only then (gpp.cpp). On a shared bus a second
// process sends each answer when it is ready, in time order, and frees its ray slot when
// the bus has taken it.
#pragma once

#include "hw/functional_frame.h"
#include "hw/local_clock.h"
#include "hw/payloads.h"
#include "hw/pipeline_timing.h"
#include "hw/ray_fifo.h"
#include "hw/unit_cycles.h"
#include "hw/vcd_writer.h"
#include "hw/watchdog.h"

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

#include <memory>
#include <optional>
#include <queue>

namespace oprt::hw {

enum class UnitState : std::uint8_t { idle = 0, sphere = 1, transform = 2, primitive = 3, stall = 4, box = 5 };

struct UnitStats {
  UnitCycles cycles;  // pipelined: each unit's issue cycles, and memory + bus stall
  std::uint64_t rays[kRayKinds] = {};
  std::optional<PipelineStats> pipeline;  // a pipelined unit's stages
};

template <typename T>
class IntersectionUnit : public sc_core::sc_module, public Waiter {
 public:
  tlm_utils::simple_target_socket<IntersectionUnit> cfg;    // configuration registers (from the bus)
  tlm_utils::simple_initiator_socket<IntersectionUnit> bus;  // answers to the GPP
  tlm_utils::simple_initiator_socket<IntersectionUnit> mem;  // its object memory
  sc_core::sc_port<RayFifoIf> fifo;

  SC_HAS_PROCESS(IntersectionUnit);
  IntersectionUnit(const sc_core::sc_module_name& name, int id, const Arch& arch,
                   const FunctionalFrame<T>& frame, VcdWriter* vcd);
  ~IntersectionUnit() override;

  int id() const { return id_; }
  const IuRegisters<T>& registers() const { return regs_; }
  UnitStats& stats();
  void reset_stats();
  std::string waiting_for() const override;

 private:
  void run();
  void cfg_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void read_memory(const VisitWork& v);
  void trace_state(UnitState s, const sc_core::sc_time& at);
  void trace_phases(const UnitRayWork* w, sc_core::sc_time at);
  void send_answer(std::uint32_t ray, const UnitRayWork* w, sc_core::sc_time& delay);
  // Pipelined: the intake (pops rays) and, unless it runs ahead, the write-back (answers).
  void run_pipelined();
  void write_back();
  void take(const RayEntry& e, Cycle t);
  sc_core::sc_time time_of(Cycle c) const { return sc_core::sc_time::from_value(cycle_.value() * static_cast<std::uint64_t>(c)); }
  Cycle cycle_of(const sc_core::sc_time& t) const { return static_cast<Cycle>((t.value() + cycle_.value() / 2) / cycle_.value()); }

  const int id_;
  const Arch& arch_;
  const FunctionalFrame<T>& frame_;
  const sc_core::sc_time cycle_;
  const std::uint32_t triangle_bytes_;
  IuRegisters<T> regs_;
  UnitStats stats_;
  LocalClock clock_;
  const bool sync_on_bus_;
  tlm::tlm_generic_payload answer_, read_;
  VcdWriter* vcd_;
  int vcd_state_ = -1;
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
