#include "hw/intersection_unit.h"

namespace oprt::hw {

using namespace sc_core;

namespace {
// A unit's cache misses contend with other units' when they share a DRAM channel, or cross
// a shared bus.
bool dram_shared(const Arch& a) {
  return a.memory.sram_bytes != 0 && (a.memory.dram.units_per_channel > 1 ||
                                      (a.memory.dram.path == DramPath::bus && a.bus.model == BusModel::shared));
}

// Nothing else observes a unit's intermediate times when its FIFO never fills, its answers
// take no bus time and its cache misses, if any, contend with no one's (local_clock.h).
LocalClock::Mode unit_clock(const Arch& a) {
  if (a.fifo_depth == 0 && a.bus.model == BusModel::ideal && !dram_shared(a) && !a.sync_every_ray)
    return LocalClock::Mode::ahead;
  return a.level == Level::lt ? LocalClock::Mode::quantum : LocalClock::Mode::exact;
}

// Whether the object memory waits until each miss is due before sending it: always where
// the unit keeps exact time; under temporal decoupling where misses contend and the bus's
// lt_arbitration asks initiators to synchronise (bus.h), as the bus's own transfers do.
bool sync_misses(const Arch& a, LocalClock::Mode m) {
  if (m == LocalClock::Mode::exact) return true;
  return m == LocalClock::Mode::quantum && dram_shared(a) && a.bus.lt_arbitration == LtArbitration::sync;
}
}  // namespace

template <typename T>
IntersectionUnit<T>::IntersectionUnit(const sc_module_name& name, int id, const Arch& arch,
                                      const SceneGeometry<T>& geometry, const FunctionalFrame<T>& frame, VcdWriter* vcd,
                                      TimelineWriter* timeline)
    : sc_module(name),
      cfg("cfg"),
      bus("bus"),
      mem("mem"),
      fifo("fifo"),
      id_(id),
      arch_(arch),
      geom_(geometry),
      frame_(frame),
      cycle_(arch.cycle_ns(), SC_NS),
      triangle_bytes_(Bytes<T>::triangle(arch.kernel)),
      trace_lead_(cycle_ * static_cast<double>(kTraceLeadCycles)),
      clock_(unit_clock(arch)),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      sync_misses_(sync_misses(arch, clock_.mode())),
      addresses_(geometry),
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
  const auto* c = reinterpret_cast<const ConfigPacket<T>*>(p.get_data_ptr());
  regs_ = *c->registers;
  cached_ = c->cached;
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
constexpr const char* kPhaseName[] = {"idle", "sphere", "transform", "primitive", "stall", "box", "node"};  // UnitState
}

template <typename T>
void IntersectionUnit<T>::trace_phases(std::uint32_t ray, const UnitRayWork* w, sc_time at) {
  const std::uint32_t transform = arch_.kernel_costs().transform;
  for_each_phase(frame_, w, static_cast<std::uint32_t>(id_), transform, [&](std::uint8_t state, std::uint64_t cycles) {
    const sc_time end = at + sc_time::from_value(cycles * cycle_.value());
    if (vcd_) trace_state(static_cast<UnitState>(state), at);
    if (timeline_) {
      if (w) timeline_->slice(track_, kPhaseName[state], at.value(), end.value(), {{"ray", ray}});
      else timeline_->run_slice(track_, kPhaseName[state], at.value(), end.value(), ray);  // sphere tests only
    }
    at = end;
  });
}

// The triangles (and, with a BVH, the nodes) a ray's visits tested: one read per ray, or per
// entered sphere when the trace kept that detail. The memory's latency is already in the
// visits' stall cycles (memory_timing.h).
template <typename T>
void IntersectionUnit<T>::read_memory(std::uint32_t sphere, std::uint64_t bytes) {
  MemoryReadPacket packet{sphere, bytes};
  read_.set_command(tlm::TLM_READ_COMMAND);
  read_.set_address(0);
  read_.set_data_ptr(reinterpret_cast<unsigned char*>(&packet));
  read_.set_data_length(static_cast<unsigned>(bytes));
  read_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  sc_time latency = SC_ZERO_TIME;
  mem->b_transport(read_, latency);
  if (read_.is_response_error())
    SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(sphere)).c_str());
}

template <typename T>
void IntersectionUnit<T>::advance_tracing(std::uint32_t ray, UnitState s, std::uint64_t cycles) {
  if (!cycles) return;
  const sc_time start = clock_.now();
  if (vcd_) trace_state(s, start);
  clock_.advance(sc_time::from_value(cycles * cycle_.value()));
  if (timeline_)
    timeline_->slice(track_, kPhaseName[static_cast<int>(s)], start.value(), clock_.now().value(), {{"ray", ray}});
}

// A ray through a cache: visit by visit, each timed by the memory from the moment its sphere
// test hits. The tests before each visit, and after the last, are the functional trace's;
// the trace's memory stall (on-chip memory's) is replaced by the cache's. Returns the cycles
// the unit spent: busy and the cache's stall.
template <typename T>
std::uint64_t IntersectionUnit<T>::trace_through_cache(std::uint32_t ray, const RayRecord<T>& r,
                                                        const UnitRayWork& w) {
  const UnitTrace<T>& ut = frame_.units[static_cast<std::uint32_t>(id_)];
  const std::uint32_t i = ut.index(&w);
  const std::uint32_t transform = arch_.kernel_costs().transform;
  const sc_time start = clock_.now();
  std::uint32_t spheres = 0, nodes = 0;
  std::uint64_t trace_stall = 0, stall = 0;
  for (std::uint32_t k = ut.visit_first[i]; k < ut.visit_first[i + 1]; ++k) {
    const VisitWork& v = ut.visits[k];
    advance_tracing(ray, UnitState::node, std::uint64_t{v.nodes_before} * frame_.node_cost);
    advance_tracing(ray, UnitState::sphere, std::uint64_t{v.spheres_before} * frame_.sphere_cost);
    nodes += v.nodes_before;
    spheres += v.spheres_before;
    trace_stall += v.stall;
    const WorkCounts again = visit_stream(geom_, regs_, r.ray, r.kind, v.entry, addresses_, stream_);
    if (again.tri_tests() != v.tri_tests || again.box_tests != v.box_tests)
      SC_REPORT_FATAL(name(), "a visit walked again for its addresses differs from the functional trace");
    const VisitCosts costs = visit_costs(arch_, again);
    if (vcd_) {
      trace_state(UnitState::transform, clock_.now());
      if (again.box_setups) trace_state(UnitState::box, clock_.now() + sc_time::from_value(transform * cycle_.value()));
    }
    const std::uint64_t bytes = std::uint64_t{v.tri_tests} * triangle_bytes_ + std::uint64_t{v.box_tests} * Bytes<T>::node;
    MemoryReadPacket packet{v.sphere, bytes, &stream_, &costs, sync_misses_, vcd_ ? vcd_state_ : -1};
    read_.set_command(tlm::TLM_READ_COMMAND);
    read_.set_address(0);
    read_.set_data_ptr(reinterpret_cast<unsigned char*>(&packet));
    read_.set_data_length(static_cast<unsigned>(bytes));
    read_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
    const sc_time visit_start = clock_.now();
    if (sync_misses_) clock_.sync();  // lt: the memory may wait, from local time
    sc_time delay = clock_.offset();
    mem->b_transport(read_, delay);
    if (read_.is_response_error())
      SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(v.sphere)).c_str());
    if (sync_misses_) clock_.resync();
    clock_.advance_to(sc_time_stamp() + delay);  // the visit's end
    stall += packet.stall;
    traced_state_ = kStateUnknown;  // the memory reported the visit's states (and stalls)
    if (timeline_) {  // the transform, then the rest of the visit with its cache stalls
      const sc_time t = visit_start + sc_time::from_value(transform * cycle_.value());
      timeline_->slice(track_, "transform", visit_start.value(), t.value(), {{"ray", ray}});
      timeline_->slice(track_, "primitive", t.value(), clock_.now().value(),
                       {{"ray", ray}, {"cache_stall", packet.stall}});
    }
  }
  advance_tracing(ray, UnitState::node, std::uint64_t{ut.node_tests[i] - nodes} * frame_.node_cost);
  advance_tracing(ray, UnitState::sphere, std::uint64_t{ut.sphere_tests[i] - spheres} * frame_.sphere_cost);
  stats_.cache_stall += stall;
  const std::uint64_t spent = w.cycles - trace_stall + stall;  // busy, and the cache's stall
  if (static_cast<std::uint64_t>((clock_.now() - start).value() / cycle_.value()) != spent)
    SC_REPORT_FATAL(name(), "a ray through the cache took other cycles than its work and its stalls");
  return spent;
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
    ++stats_.rays[kind];
    const UnitTrace<T>& ut = frame_.units[unit];
    if (cached_ && w && ut.visit_first[ut.index(w) + 1] > ut.visit_first[ut.index(w)]) {
      stats_.charged += trace_through_cache(e.ray, r, *w);  // the trace keeps the detail for caches (Gpp)
    } else {
      if (w && frame_.detailed) {
        const std::uint32_t i = ut.index(w);
        for (std::uint32_t k = ut.visit_first[i]; k < ut.visit_first[i + 1]; ++k) {
          const VisitWork& v = ut.visits[k];
          read_memory(v.sphere, std::uint64_t{v.tri_tests} * triangle_bytes_ + std::uint64_t{v.box_tests} * Bytes<T>::node);
        }
      } else if (w) {
        read_memory(kNone, w->bytes);
      }
      if (vcd_ || timeline_) trace_phases(e.ray, w, clock_.now());
      const std::uint64_t cycles = frame_.cycles(w, unit);
      stats_.charged += cycles;
      clock_.advance(sc_time::from_value(cycles * cycle_.value()));
    }
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
      stats_.bus_stall += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
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
