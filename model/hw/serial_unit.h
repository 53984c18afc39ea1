// SerialUnit: the paper's intersection unit, one adder, one multiplier and a register file,
// one operation at a time. It pops rays from its FIFO, tests each against its spheres
// (registers written by the GPP each frame), carries the ray into a sphere's local frame on
// a hit and tests that sphere's triangles streamed from its object memory, then answers the
// GPP over the bus: the nearest hit of a primary ray, or whether a shadow ray is occluded
// (it stops at the first occluder).
//
// Its time on a ray is timing/serial_unit_timing.h's, which `lt` and the analytic level
// call too. On-chip memory: the ray's cycles are known when it starts (the trace holds
// them), so the unit waits them out in one step (phases are only reported to the waveform
// and the timeline, with their times): one simulation event per ray at most, none while
// idle, and none at all per ray when nothing can observe the unit's intermediate times
// (local_clock.h, `ahead`). When its spheres do not fit its object memory, the memory is a
// cache: the unit then sends each entered sphere's reads with their addresses and consumes
// them as the memory times them (object_memory_model.h).
#pragma once

#include "hw/intersection_unit.h"
#include "hw/local_clock.h"
#include "timing/serial_unit_timing.h"
#include "timing/visit_stream.h"
#include "trace/timeline.h"
#include "trace/vcd_writer.h"

namespace oprt::hw {

using timing::CachedVisits, timing::GeometryAddresses, timing::UnitState;

template <typename T>
class SerialUnit : public IntersectionUnit<T> {
 public:
  SC_HAS_PROCESS(SerialUnit);
  SerialUnit(const sc_core::sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
             const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline = nullptr);

 private:
  using Base = IntersectionUnit<T>;
  void run();
  // The ray's phases and visits through the cache (serial_ray), advancing the clock.
  void trace_ray(std::uint32_t ray, const UnitRayWork* w);
  void trace_state(UnitState s, const sc_core::sc_time& at);

  // How far a unit running ahead may lead simulation time while the trace writer is over
  // its budget: the units behind keep going (no wait) until they lead by as much.
  static constexpr std::uint64_t kTraceLeadCycles = std::uint64_t{1} << 13;
  const sc_core::sc_time trace_lead_;
  LocalClock clock_;
  const bool sync_on_bus_;
  const bool sync_misses_;  // the memory waits until each miss is due (shared DRAM channel or bus)
  const GeometryAddresses<T> addresses_;
  CachedVisits<T> visits_;  // timing visits through a cache
  VcdWriter* vcd_;     // null when its state is not traced
  VcdWriter* writer_;  // the waveform writer, whatever it traces (its budget, vcd_writer.h)
  int vcd_state_ = -1;
  UnitState traced_state_ = UnitState::idle;  // the last state reported to vcd_
  TimelineWriter* timeline_;  // null when not traced
  int track_ = -1;
};

extern template class SerialUnit<float>;
extern template class SerialUnit<double>;

}  // namespace oprt::hw
