// What every intersection unit has, whatever is inside it: its sockets and its registers.
// Two modules build on it, one file each: SerialUnit (the paper's IU, serial_unit.h) and
// PipelinedUnit (its future work, pipelined_unit.h). Both sit behind the same sockets:
//   cfg   configuration registers, written by the GPP over the bus (ConfigExtension)
//   bus   answers to the GPP (WireAnswer bytes)
//   mem   its object memory: a visit's reads (VisitReadExtension)
//   fifo  its ray FIFO (RayFifoIf), which it pops
// The work itself was traced before the frame's timing (ref/functional_frame.h); a unit
// looks up its record for each ray it pops, times it with the plain-C++ unit timing that
// every level shares, and sends the recorded answer.
#pragma once

#include "hw/extensions.h"
#include "hw/local_clock.h"
#include "hw/ray_fifo.h"
#include "hw/watchdog.h"
#include "ref/functional_frame.h"
#include "timing/pipeline_timing.h"

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

#include <optional>
#include <string>

namespace oprt::hw {

using timing::BurstConsumer, timing::Cycle, timing::PipelineStats, timing::VisitStream;

// What a unit measured in the frame, beside its work (the trace's).
struct UnitStats {
  std::uint64_t charged = 0;    // serial: busy and memory stall, summed ray by ray
  std::uint64_t bus_stall = 0;  // serial: waiting for the shared bus to take its answers
  // Through an object memory that is a cache (--sram): its stall replaces the trace's, which
  // is on-chip memory's.
  std::uint64_t cache_stall = 0;
  std::optional<PipelineStats> pipeline;  // a pipelined unit's units (its cycles are theirs)
  std::uint64_t rays[kRayKinds] = {};
};

// A unit's cache misses contend with other units' when they share a DRAM channel (also
// behind the engine's memory port, memory.dram.path "external": then the memory there sees
// every unit's requests in time order), or cross a shared bus.
inline bool dram_shared(const Arch& a) {
  return a.memory.sram_bytes != 0 && (a.memory.dram.units_per_channel > 1 ||
                                      (a.memory.dram.path == DramPath::bus && a.bus.model == BusModel::shared));
}

// Nothing else observes a unit's intermediate times when its FIFO never fills, its answers
// take no bus time and its cache misses, if any, contend with no one's (local_clock.h).
inline LocalClock::Mode unit_clock(const Arch& a) {
  if (a.fifo_depth == 0 && a.bus.model == BusModel::ideal && !dram_shared(a) && !a.sync_every_ray)
    return LocalClock::Mode::ahead;
  return a.level == Level::lt ? LocalClock::Mode::quantum : LocalClock::Mode::exact;
}

template <typename T>
class IntersectionUnit : public sc_core::sc_module, public Waiter {
 public:
  tlm_utils::simple_target_socket<IntersectionUnit> cfg;
  tlm_utils::simple_initiator_socket<IntersectionUnit> bus;
  tlm_utils::simple_initiator_socket<IntersectionUnit> mem;
  sc_core::sc_port<RayFifoIf> fifo;

  int id() const { return id_; }
  const IuRegisters<T>& registers() const { return regs_; }
  virtual UnitStats& stats() { return stats_; }
  virtual void reset_stats() { stats_ = UnitStats{}; }
  // The earliest time the unit may still report to the waveform (a pipelined unit reports
  // its units' work when it takes a ray, ahead of simulation time); no limit by default.
  virtual sc_core::sc_time trace_floor() const { return sc_core::sc_max_time(); }
  std::string waiting_for() const override;

 protected:
  IntersectionUnit(const sc_core::sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
                   const FunctionalFrame<T>& frame);

  // Answer ray `ray` to the GPP over the bus (delay: annotated, as b_transport's).
  void send_answer(std::uint32_t ray, const UnitRayWork* w, sc_core::sc_time& delay);
  // Reads of `bytes` from object memory; with a stream, the memory times its bursts from
  // `request` and hands their arrivals to `unit`; returns when the unit is done with the
  // last (the request itself without a stream).
  // `horizon`: no later read asks for anything before it.
  Cycle read(std::uint32_t sphere, std::uint64_t bytes, const VisitStream* stream, BurstConsumer* unit, Cycle request,
             bool sync, Cycle horizon);
  sc_core::sc_time time_of(Cycle c) const { return sc_core::sc_time::from_value(cycle_.value() * static_cast<std::uint64_t>(c)); }
  Cycle cycle_of(const sc_core::sc_time& t) const { return static_cast<Cycle>((t.value() + cycle_.value() / 2) / cycle_.value()); }
  std::string its_fifo() const;

  const int id_;
  const Arch& arch_;
  const SceneGeometry<T>& geom_;
  const FunctionalFrame<T>& frame_;
  const sc_core::sc_time cycle_;
  IuRegisters<T> regs_;
  bool cached_ = false;  // its object memory is a cache this frame (ConfigExtension)
  UnitStats stats_;
  // For the watchdog: what the process is doing (plain stores, no events).
  enum class Activity : std::uint8_t { waiting_for_ray, tracing, answering, waiting_for_slot } activity_ =
      Activity::waiting_for_ray;
  std::uint32_t ray_ = 0;

 private:
  void cfg_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  tlm::tlm_generic_payload answer_, read_;
  ByteBuffer answer_bytes_, read_bytes_;
};

extern template class IntersectionUnit<float>;
extern template class IntersectionUnit<double>;

}  // namespace oprt::hw
