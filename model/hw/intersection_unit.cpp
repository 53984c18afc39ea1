#include "hw/intersection_unit.h"

namespace oprt::hw {

using namespace sc_core;

namespace {
// Nothing else observes a unit's intermediate times when its FIFO never fills and its
// answers take no bus time (local_clock.h).
LocalClock::Mode unit_clock(const Arch& a) {
  if (a.fifo_depth == 0 && a.bus.model == BusModel::ideal && !a.sync_every_ray) return LocalClock::Mode::ahead;
  return a.level == Level::lt ? LocalClock::Mode::quantum : LocalClock::Mode::exact;
}
}  // namespace

template <typename T>
IntersectionUnit<T>::IntersectionUnit(const sc_module_name& name, int id, const Arch& arch,
                                      const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline)
    : sc_module(name),
      cfg("cfg"),
      bus("bus"),
      mem("mem"),
      fifo("fifo"),
      id_(id),
      arch_(arch),
      frame_(frame),
      cycle_(arch.cycle_ns(), SC_NS),
      triangle_bytes_(Bytes<T>::triangle(arch.kernel)),
      trace_lead_(cycle_ * static_cast<double>(kTraceLeadCycles)),
      clock_(unit_clock(arch)),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      vcd_(vcd),
      timeline_(timeline) {
  cfg.register_b_transport(this, &IntersectionUnit::cfg_transport);
  if (vcd_ && (vcd_state_ = vcd_->add(this->name(), "state", 3)) == VcdWriter::kNotTraced) vcd_ = nullptr;
  if (timeline_ && (track_ = timeline_->track(this->name(), "state", "IU " + std::to_string(id))) ==
                       TimelineWriter::kNotTraced)
    timeline_ = nullptr;
  reset_stats();
  SC_THREAD(run);
}

template <typename T>
void IntersectionUnit<T>::reset_stats() {
  stats_ = UnitStats{};
}

template <typename T>
void IntersectionUnit<T>::cfg_transport(tlm::tlm_generic_payload& p, sc_time&) {
  if (p.get_command() != tlm::TLM_WRITE_COMMAND || p.get_address() != 0) {
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  regs_ = *reinterpret_cast<const ConfigPacket<T>*>(p.get_data_ptr())->registers;
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

// The unit reports its own state in time order, so a report equal to the last one changes
// nothing and is skipped (most rays are sphere tests only, back to back).
template <typename T>
void IntersectionUnit<T>::trace_state(UnitState s, const sc_time& at) {
  if (s == traced_state_) return;
  traced_state_ = s;
  vcd_->change(vcd_state_, at.value(), static_cast<std::uint64_t>(s));
}

namespace {
constexpr const char* kPhaseName[] = {"idle", "sphere", "transform", "primitive", "stall", "box"};
}

template <typename T>
void IntersectionUnit<T>::trace_phases(std::uint32_t ray, const UnitRayWork* w, sc_time at) {
  const std::uint32_t transform = arch_.kernel_costs().transform;
  for_each_phase(frame_, w, static_cast<std::uint32_t>(id_), transform, [&](std::uint8_t state, std::uint64_t cycles) {
    const sc_time end = at + cycle_ * static_cast<double>(cycles);
    if (vcd_) trace_state(static_cast<UnitState>(state), at);
    if (timeline_) {
      if (w) timeline_->slice(track_, kPhaseName[state], at.value(), end.value(), {{"ray", ray}});
      else timeline_->run_slice(track_, kPhaseName[state], at.value(), end.value(), ray);  // sphere tests only
    }
    at = end;
  });
}

// One burst per entered sphere: its triangles (and, with a BVH, its nodes) as tested. The
// memory's latency is already in the visit's stall cycles (memory_timing.h).
template <typename T>
void IntersectionUnit<T>::read_memory(const VisitWork& v) {
  const std::uint64_t bytes = std::uint64_t{v.tri_tests} * triangle_bytes_ + std::uint64_t{v.box_tests} * Bytes<T>::node;
  MemoryReadPacket packet{v.sphere, bytes};
  read_.set_command(tlm::TLM_READ_COMMAND);
  read_.set_address(0);
  read_.set_data_ptr(reinterpret_cast<unsigned char*>(&packet));
  read_.set_data_length(static_cast<unsigned>(bytes));
  read_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  sc_time latency = SC_ZERO_TIME;
  mem->b_transport(read_, latency);
  if (read_.is_response_error())
    SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(v.sphere)).c_str());
}

template <typename T>
void IntersectionUnit<T>::run() {
  const auto unit = static_cast<std::uint32_t>(id_);
  for (;;) {
    RayEntry e;
    while (!fifo->pop(e, clock_.now())) {
      if (clock_.offset() != SC_ZERO_TIME && clock_.mode() == LocalClock::Mode::quantum) {
        clock_.sync();  // catch up first, then look again: a ray written meanwhile would be missed otherwise
        continue;
      }
      if (vcd_) trace_state(UnitState::idle, clock_.now());
      activity_ = Activity::waiting_for_ray;
      wait(fifo->pushed_event());
      clock_.resync();
    }
    activity_ = Activity::tracing;
    ray_ = e.ray;
    clock_.advance_to(e.avail);
    const RayRecord<T>& r = frame_.rays[e.ray];
    const int kind = static_cast<int>(r.kind);
    const UnitRayWork* w = frame_.find(e.ray, unit);
    if (w)
      for (std::uint32_t i = w->first_visit; i < w->first_visit + w->visits; ++i)
        read_memory(frame_.units[unit].visits[i]);
    if (vcd_ || timeline_) trace_phases(e.ray, w, clock_.now());
    const UnitCycles c = frame_.breakdown(w, unit);
    ++stats_.rays[kind];
    clock_.advance(cycle_ * static_cast<double>(c.busy() + c.stall));
    stats_.cycles += c;
    // Running ahead, with the trace writer full: let the units behind catch up (vcd_writer.h).
    if (vcd_ && vcd_->full() && clock_.mode() == LocalClock::Mode::ahead && clock_.offset() > trace_lead_ &&
        vcd_->over_budget())
      clock_.catch_up();

    // Answer the GPP. The unit waits for its transfer: time on the bus is a stall.
    AnswerPacket<T> a;
    a.ray = e.ray;
    a.unit = unit;
    const UnitAnswer<T> answer = frame_.answer(w, unit);
    a.occluded = answer.occluded;
    a.hit = answer.hit;
    answer_.set_command(tlm::TLM_WRITE_COMMAND);
    answer_.set_address(addr::gpp_hits);
    answer_.set_data_ptr(reinterpret_cast<unsigned char*>(&a));
    answer_.set_data_length(r.kind == RayKind::primary ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer);
    answer_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
    const sc_time before = clock_.now();
    if (vcd_ && arch_.bus.model == BusModel::shared) trace_state(UnitState::stall, before);
    if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
    sc_time delay = clock_.offset();
    const sc_time sim = sc_time_stamp();
    activity_ = Activity::answering;
    bus->b_transport(answer_, delay);
    if (answer_.is_response_error()) SC_REPORT_FATAL(name(), "answer to the GPP failed");
    clock_.advance_to(sim + delay);  // decoupled: the transfer's end; at: already waited
    if (arch_.bus.model == BusModel::shared) {
      stats_.cycles.stall += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
      if (timeline_) timeline_->slice(track_, "bus wait", before.value(), clock_.now().value(), {{"ray", e.ray}});
    }
  }
}

template <typename T>
std::string IntersectionUnit<T>::waiting_for() const {
  const auto* f = dynamic_cast<const sc_object*>(fifo.get_interface());
  const std::string its_fifo = "its FIFO " + std::string(f ? f->name() : "?") + " " + fifo->fill_state();
  switch (activity_) {
    case Activity::waiting_for_ray: return "waiting for a ray; " + its_fifo;
    case Activity::tracing: return "tracing ray " + std::to_string(ray_) + "; " + its_fifo;
    case Activity::answering: return "waiting for the bus to take its answer to ray " + std::to_string(ray_) + "; " + its_fifo;
  }
  return its_fifo;
}

template class IntersectionUnit<float>;
template class IntersectionUnit<double>;

}  // namespace oprt::hw
