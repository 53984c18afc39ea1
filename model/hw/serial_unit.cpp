#include "hw/serial_unit.h"

namespace oprt::hw {

using timing::BurstConsumer, timing::Cycle, timing::VisitStream, timing::cached_visit, timing::serial_ray,
    timing::to_string;

using namespace sc_core;

namespace {
// Whether the object memory waits until each miss is due before sending it: always where
// the unit keeps exact time; under temporal decoupling where misses contend and the bus's
// lt_arbitration asks initiators to synchronise (bus.h), as the bus's own transfers do.
bool sync_misses(const Arch& a, LocalClock::Mode m) {
  if (m == LocalClock::Mode::exact) return dram_shared(a);
  return m == LocalClock::Mode::quantum && dram_shared(a) && a.bus.lt_arbitration == LtArbitration::sync;
}
}  // namespace

template <typename T>
SerialUnit<T>::SerialUnit(const sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
                          const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline)
    : Base(name, id, arch, geometry, frame),
      trace_lead_(this->cycle_ * static_cast<double>(kTraceLeadCycles)),
      clock_(unit_clock(arch)),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      sync_misses_(sync_misses(arch, clock_.mode())),
      addresses_(geometry),
      visits_{geometry, this->regs_, addresses_, arch, {}, 0},
      vcd_(vcd),
      writer_(vcd),
      timeline_(timeline) {
  if (vcd_ && (vcd_state_ = vcd_->add(this->name(), "state", 3)) == VcdWriter::kNotTraced) vcd_ = nullptr;
  if (timeline_ && (track_ = timeline_->track(this->name(), "state", "IU " + std::to_string(id))) ==
                       TimelineWriter::kNotTraced)
    timeline_ = nullptr;
  SC_THREAD(run);
}

// The unit reports its own state in time order, so a report equal to the last one changes
// nothing and is skipped (most rays are sphere tests only, back to back).
template <typename T>
void SerialUnit<T>::trace_state(UnitState s, const sc_time& at) {
  if (s == traced_state_) return;
  traced_state_ = s;
  vcd_->change(vcd_state_, at.value(), static_cast<std::uint64_t>(s));
}

// A ray whose phases are traced, or whose visits go through a cache: serial_ray, phase by
// phase. Phases are reported with their times; the clock advances once, to the ray's end,
// except around a visit through the cache, whose memory may wait for its misses' times.
template <typename T>
void SerialUnit<T>::trace_ray(std::uint32_t ray, const UnitRayWork* w) {
  const auto unit = static_cast<std::uint32_t>(this->id_);
  const RayRecord<T>& r = this->frame_.rays[ray];
  visits_.stall = 0;
  auto phase = [&](UnitState s, Cycle from, Cycle to) {
    if (vcd_) trace_state(s, this->time_of(from));
    if (!timeline_) return;
    if (w) timeline_->slice(track_, to_string(s), this->time_of(from).value(), this->time_of(to).value(), {{"ray", ray}});
    else timeline_->run_slice(track_, to_string(s), this->time_of(from).value(), this->time_of(to).value(), ray);
  };
  // The memory reports the visit's states as they happen (never before simulation time: a
  // miss sent late by a full miss window can make the unit wait from a time the memory has
  // already passed).
  auto state = [&](UnitState s, Cycle t) {
    if (vcd_) trace_state(s, std::max(this->time_of(t), sc_time_stamp()));
  };
  auto visit = [&](const VisitWork& v, Cycle t) {
    clock_.advance_to(this->time_of(t));
    if (sync_misses_) clock_.sync();  // lt: the memory may wait, from local time
    const Cycle start = this->cycle_of(clock_.now());
    const std::uint64_t stall_before = visits_.stall;
    const Cycle end = cached_visit(visits_, r, v, start,
                                   [&](const VisitStream& s, Cycle request, BurstConsumer& c) {
                                     const std::uint64_t bytes = std::uint64_t{v.tri_tests} * Bytes<T>::triangle(this->arch_.kernel) +
                                                                 std::uint64_t{v.box_tests} * Bytes<T>::node;
                                     return this->read(this->regs_.sphere[v.entry], bytes, &s, &c, request, sync_misses_, request);
                                   },
                                   state);
    if (sync_misses_) clock_.resync();
    clock_.advance_to(this->time_of(end));
    if (timeline_) {  // the transform, then the rest of the visit with its cache stalls
      const Cycle transformed = start + this->arch_.kernel_costs().transform;
      timeline_->slice(track_, "transform", this->time_of(start).value(), this->time_of(transformed).value(), {{"ray", ray}});
      timeline_->slice(track_, "primitive", this->time_of(transformed).value(), this->time_of(end).value(),
                       {{"ray", ray}, {"cache_stall", visits_.stall - stall_before}});
    }
    return end;
  };
  const sc_time start = clock_.now();
  const Cycle end = serial_ray(this->frame_, unit, w, this->cycle_of(start), this->arch_.kernel_costs().transform,
                               this->cached_, visit, phase);
  clock_.advance_to(this->time_of(end));
  this->stats_.cache_stall += visits_.stall;
  this->stats_.charged += static_cast<std::uint64_t>(end - this->cycle_of(start));
}

template <typename T>
void SerialUnit<T>::run() {
  const auto unit = static_cast<std::uint32_t>(this->id_);
  for (;;) {
    RayEntry e;
    while (!this->fifo->pop(e, clock_.now())) {
      if (clock_.offset() != SC_ZERO_TIME && clock_.mode() == LocalClock::Mode::quantum) {
        clock_.sync();  // catch up first, then look again: a ray written meanwhile would be missed otherwise
        continue;
      }
      if (vcd_) trace_state(UnitState::idle, clock_.now());
      this->activity_ = Base::Activity::waiting_for_ray;
      wait(this->fifo->pushed_event());
      clock_.resync();
    }
    this->activity_ = Base::Activity::tracing;
    this->ray_ = e.ray;
    clock_.advance_to(e.avail);
    const int kind = static_cast<int>(this->frame_.rays[e.ray].kind);
    const UnitRayWork* w = this->frame_.find(e.ray, unit);
    ++this->stats_.rays[kind];
    const bool through_cache = this->cached_ && w && this->frame_.visits_of(unit, this->frame_.units[unit].index(w)).size() > 0;
    if (through_cache || vcd_ || timeline_) {
      if (w && !through_cache) this->read(kNone, w->bytes, nullptr, nullptr, 0, false, 0);
      trace_ray(e.ray, w);
    } else {
      if (w) this->read(kNone, w->bytes, nullptr, nullptr, 0, false, 0);  // its triangles and nodes, from on-chip memory
      const std::uint64_t cycles = this->frame_.cycles(w, unit);
      this->stats_.charged += cycles;
      clock_.advance(sc_time::from_value(cycles * this->cycle_.value()));
    }
    // Running ahead, with the trace writer full: let the units behind catch up (vcd_writer.h).
    // (Whether or not its own state is traced: its FIFO's pops and its memory's misses are.)
    if (writer_ && writer_->full() && clock_.mode() == LocalClock::Mode::ahead && clock_.offset() > trace_lead_ &&
        writer_->over_budget())
      clock_.catch_up();

    // Answer the GPP. The unit waits for its transfer: time on the bus is a stall.
    const sc_time before = clock_.now();
    if (vcd_ && this->arch_.bus.model == BusModel::shared) trace_state(UnitState::stall, before);
    if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
    sc_time delay = clock_.offset();
    const sc_time sim = sc_time_stamp();
    this->activity_ = Base::Activity::answering;
    this->send_answer(e.ray, w, delay);
    clock_.advance_to(sim + delay);  // decoupled: the transfer's end; at: already waited
    if (this->arch_.bus.model == BusModel::shared) {
      this->stats_.bus_stall += static_cast<std::uint64_t>((clock_.now() - before) / this->cycle_ + 0.5);
      if (timeline_) timeline_->slice(track_, "bus wait", before.value(), clock_.now().value(), {{"ray", e.ray}});
    }
  }
}

template class SerialUnit<float>;
template class SerialUnit<double>;

}  // namespace oprt::hw
