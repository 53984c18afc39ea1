#include "hw/intersection_unit.h"

namespace oprt::hw {

using namespace sc_core;

template <typename T>
IntersectionUnit<T>::IntersectionUnit(const sc_module_name& name, int id, const Arch& arch,
                                      const SceneGeometry<T>& geometry, const std::vector<RayRecord<T>>& rays,
                                      VcdWriter* vcd)
    : sc_module(name),
      cfg("cfg"),
      bus("bus"),
      mem("mem"),
      fifo("fifo"),
      id_(id),
      arch_(arch),
      geom_(geometry),
      rays_(rays),
      cycle_(arch.cycle_ns(), SC_NS),
      clock_(arch.level == Level::lt),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      vcd_(vcd) {
  cfg.register_b_transport(this, &IntersectionUnit::cfg_transport);
  if (vcd_) vcd_state_ = vcd_->add(this->name(), "state", 3);
  reset_stats();
  SC_THREAD(run);
}

template <typename T>
void IntersectionUnit<T>::reset_stats() {
  stats_.cycles = {};
  for (int k = 0; k < kRayKinds; ++k) {
    stats_.rays[k] = 0;
    stats_.per_sphere[k].assign(geom_.sphere_count(), WorkCounts{});
  }
  stats_.last_answer = SC_ZERO_TIME;
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

template <typename T>
void IntersectionUnit<T>::trace_state(UnitState s, const sc_time& at) {
  vcd_->change(vcd_state_, at.value(), static_cast<std::uint64_t>(s));
}

template <typename T>
void IntersectionUnit<T>::read_memory(std::uint32_t sphere, std::uint64_t bytes) {
  MemoryReadPacket packet{sphere, bytes};
  read_.set_command(tlm::TLM_READ_COMMAND);
  read_.set_address(0);
  read_.set_data_ptr(reinterpret_cast<unsigned char*>(&packet));
  read_.set_data_length(static_cast<unsigned>(bytes));
  read_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  sc_time latency = SC_ZERO_TIME;  // the latency enters through stream_stall(), per triangle
  mem->b_transport(read_, latency);
  if (read_.is_response_error())
    SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(sphere)).c_str());
}

template <typename T>
void IntersectionUnit<T>::run() {
  StageLog* log = arch_.memory.model == MemoryModel::latency ? &log_ : nullptr;
  sc_time phase_at;
  auto phase = [&](UnitState s, std::uint64_t cycles) {  // VCD only
    if (!cycles) return;
    trace_state(s, phase_at);
    phase_at += cycle_ * static_cast<double>(cycles);
  };
  for (;;) {
    RayEntry e;
    while (!fifo->pop(e, clock_.now())) {
      if (clock_.offset() != SC_ZERO_TIME) {  // catch up first, then look again: a ray
        clock_.sync();                         // written meanwhile would be missed otherwise
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
    const RayRecord<T>& r = rays_[e.ray];
    const int kind = static_cast<int>(r.kind);
    UnitCycles c;
    phase_at = clock_.now();
    auto visit = [&](const SphereVisit& v) {
      std::uint64_t bytes = 0;
      const UnitCycles vc = charge_visit<T>(v, arch_, stats_.per_sphere[kind], bytes);
      c += vc;
      if (v.work.transforms) read_memory(v.sphere, bytes);
      if (vcd_) {  // a BVH interleaves box and triangle tests; the trace shows their totals
        phase(UnitState::sphere, vc.sphere);
        phase(UnitState::transform, vc.transform);
        phase(UnitState::box, vc.box);
        phase(UnitState::primitive, vc.primitive);
        phase(UnitState::stall, vc.stall);
      }
    };
    AnswerPacket<T> a;
    a.ray = e.ray;
    a.unit = static_cast<std::uint32_t>(id_);
    if (r.kind == RayKind::primary) a.hit = trace_nearest(geom_, regs_, r.ray, visit, log);
    else a.occluded = trace_any(geom_, regs_, r.ray, visit, log);
    ++stats_.rays[kind];
    clock_.advance(cycle_ * static_cast<double>(c.busy() + c.stall));
    stats_.cycles += c;

    // Answer the GPP. The unit waits for its transfer: time on the bus is a stall.
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
    const sc_time after = clock_.now();
    const auto bus_cycles = static_cast<std::uint64_t>((after - before) / cycle_ + 0.5);
    stats_.cycles.stall += bus_cycles;
    stats_.last_answer = after;
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
