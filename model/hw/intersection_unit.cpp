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

// A pipelined unit's waveform: per stage its state, its queues' occupancy and its rays in
// flight, under the unit's `stage` scope (a signal group of its own).
template <typename T>
class IntersectionUnit<T>::Trace : public PipelineTrace {
 public:
  Trace(VcdWriter& vcd, const std::string& unit, std::uint64_t cycle_ps) : vcd_(vcd), cycle_(cycle_ps) {
    const std::string scope = unit + ".stage";
    for (int s = 0; s < kPipeStages; ++s) state_[s] = vcd.add(scope, to_string(static_cast<PipeStage>(s)), 2);
    queue_[0] = vcd.add_counter(scope, "transform_queue", 16);
    queue_[1] = vcd.add_counter(scope, "triangle_queue", 16);
    in_flight_ = vcd.add_counter(scope, "rays_in_flight", 16);
  }
  void stage(PipeStage s, Cycle t, StageState st) override {
    vcd_.change(state_[static_cast<int>(s)], ps(t), static_cast<std::uint64_t>(st));
  }
  void queue(int q, Cycle t, int delta) override { vcd_.change_by(queue_[q], ps(t), delta); }
  void in_flight(Cycle t, int delta) override { vcd_.change_by(in_flight_, ps(t), delta); }

 private:
  std::uint64_t ps(Cycle t) const { return static_cast<std::uint64_t>(t) * cycle_; }
  VcdWriter& vcd_;
  std::uint64_t cycle_;
  int state_[kPipeStages] = {}, queue_[2] = {}, in_flight_ = 0;
};

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
      writer_(vcd),
      timeline_(timeline) {
  cfg.register_b_transport(this, &IntersectionUnit::cfg_transport);
  if (arch.iu.model == IuModel::pipelined) {
    // The waveform shows each stage (Trace); the timeline only the GPP and the bus: a
    // pipeline's rays overlap, which a track of nested slices cannot show.
    timeline_ = nullptr;
    if (vcd_) pipe_trace_ = std::make_unique<Trace>(*vcd_, this->name(), cycle_.value());
    pipe_ = std::make_unique<PipelinedUnitTiming>(pipeline_config(arch, triangle_bytes_), pipe_trace_.get());
    reset_stats();
    SC_THREAD(run_pipelined);
    if (arch.bus.model != BusModel::ideal) SC_THREAD(write_back);
    return;
  }
  if (vcd_ && (vcd_state_ = vcd_->add(this->name(), "state", 3)) == VcdWriter::kNotTraced) vcd_ = nullptr;
  if (timeline_ && (track_ = timeline_->track(this->name(), "state", "IU " + std::to_string(id))) ==
                       TimelineWriter::kNotTraced)
    timeline_ = nullptr;
  reset_stats();
  SC_THREAD(run);
}

template <typename T>
IntersectionUnit<T>::~IntersectionUnit() = default;

template <typename T>
void IntersectionUnit<T>::reset_stats() {
  stats_ = UnitStats{};
  if (pipe_) pipe_->reset_stats();
}

template <typename T>
UnitStats& IntersectionUnit<T>::stats() {
  if (pipe_) stats_.pipeline = pipe_->stats();  // the stages work side by side (testbench.cpp)
  return stats_;
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
  for (const VisitWork& v : frame_.visits_of(static_cast<std::uint32_t>(id_), i)) {
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
    const std::uint32_t sphere = regs_.sphere[v.entry];
    MemoryReadPacket packet{sphere, bytes, &stream_, &costs, sync_misses_, vcd_ ? vcd_state_ : -1};
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
      SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(sphere)).c_str());
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
  const auto unit = static_cast<std::uint32_t>(id_);
  advance_tracing(ray, UnitState::node, std::uint64_t{frame_.node_tests_of(unit, i) - nodes} * frame_.node_cost);
  advance_tracing(ray, UnitState::sphere, std::uint64_t{frame_.sphere_tests_of(unit, i) - spheres} * frame_.sphere_cost);
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
    if (cached_ && w && frame_.visits_of(unit, ut.index(w)).size() > 0) {
      stats_.charged += trace_through_cache(e.ray, r, *w);  // the trace keeps the detail for caches (Gpp)
    } else {
      if (w && frame_.detailed) {
        const std::uint32_t i = ut.index(w);
        for (const VisitWork& v : frame_.visits_of(static_cast<std::uint32_t>(id_), i)) {
          read_memory(regs_.sphere[v.entry], std::uint64_t{v.tri_tests} * triangle_bytes_ + std::uint64_t{v.box_tests} * Bytes<T>::node);
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
    // (Whether or not its own state is traced: its FIFO's pops and its memory's misses are.)
    if (writer_ && writer_->full() && clock_.mode() == LocalClock::Mode::ahead && clock_.offset() > trace_lead_ &&
        writer_->over_budget())
      clock_.catch_up();

    // Answer the GPP. The unit waits for its transfer: time on the bus is a stall.
    const sc_time before = clock_.now();
    if (vcd_ && arch_.bus.model == BusModel::shared) trace_state(UnitState::stall, before);
    if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
    sc_time delay = clock_.offset();
    const sc_time sim = sc_time_stamp();
    activity_ = Activity::answering;
    send_answer(e.ray, w, delay);
    clock_.advance_to(sim + delay);  // decoupled: the transfer's end; at: already waited
    if (arch_.bus.model == BusModel::shared) {
      stats_.bus_stall += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
      if (timeline_) timeline_->slice(track_, "bus wait", before.value(), clock_.now().value(), {{"ray", e.ray}});
    }
  }
}

template <typename T>
void IntersectionUnit<T>::send_answer(std::uint32_t ray, const UnitRayWork* w, sc_time& delay) {
  const auto unit = static_cast<std::uint32_t>(id_);
  AnswerPacket<T> a;
  a.ray = ray;
  a.unit = unit;
  const UnitAnswer<T> answer = frame_.answer(w, unit);
  a.occluded = answer.occluded;
  a.hit = answer.hit;
  answer_.set_command(tlm::TLM_WRITE_COMMAND);
  answer_.set_address(addr::gpp_hits);
  answer_.set_data_ptr(reinterpret_cast<unsigned char*>(&a));
  answer_.set_data_length(frame_.rays[ray].kind == RayKind::primary ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer);
  answer_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  bus->b_transport(answer_, delay);
  if (answer_.is_response_error()) SC_REPORT_FATAL(name(), "answer to the GPP failed");
}

// The pipeline takes ray e at cycle t: read the spheres it entered from object memory,
// time it, and answer (at once, annotated, on an ideal bus; on a shared one through the
// write-back process, at the answer's time).
template <typename T>
void IntersectionUnit<T>::take(const RayEntry& e, Cycle t) {
  const auto unit = static_cast<std::uint32_t>(id_);
  ray_ = e.ray;
  const UnitRayWork* w = frame_.find(e.ray, unit);
  const auto rv = frame_.ray_visits(w, unit);  // the trace keeps the detail for a pipeline (Gpp)
  for (const VisitWork& v : rv.visits)
    read_memory(regs_.sphere[v.entry], std::uint64_t{v.tri_tests} * triangle_bytes_);
  const PipelinedUnitTiming::Taken k =
      pipe_->take(t, cycle_of(e.avail), rv.sphere_tests, rv.visits.first, rv.visits.size());
  ++stats_.rays[static_cast<int>(frame_.rays[e.ray].kind)];
  // An ideal bus takes the answer at its time, whenever it is sent: send it now, annotated
  // with its time (the GPP acts on it only then), and the ray's slot is free at that time.
  if (arch_.bus.model == BusModel::ideal) {
    pipe_->retire(k.handle, k.done, k.done);
    sc_time delay = time_of(k.done) - sc_time_stamp();
    send_answer(e.ray, w, delay);
    return;
  }
  answers_.push({k.done, e.ray, k.handle});
  answer_queued_.notify();
}

// How far ahead of simulation time the pipeline may take a ray: `ahead`, without limit;
// `quantum` (lt), up to the global quantum, as a decoupled serial unit runs; `exact`, not
// at all (the ray leaves its FIFO at the simulated time the pipeline takes it).
template <typename T>
void IntersectionUnit<T>::run_pipelined() {
  const LocalClock::Mode mode = clock_.mode();
  for (;;) {
    const Cycle ready = pipe_->ready();
    if (ready == PipelinedUnitTiming::kNever) {  // every ray slot waits for its answer to leave
      activity_ = Activity::waiting_for_slot;
      wait(slot_freed_);
      continue;
    }
    const sc_time at = time_of(ready);
    const sc_time lead = mode == LocalClock::Mode::ahead     ? sc_max_time()
                         : mode == LocalClock::Mode::quantum ? tlm_utils::tlm_quantumkeeper::get_global_quantum()
                                                             : SC_ZERO_TIME;
    if (at > sc_time_stamp() && at - sc_time_stamp() > lead) {
      activity_ = Activity::tracing;
      wait(at - sc_time_stamp());
      continue;
    }
    RayEntry e;
    const sc_time now = std::max(at, sc_time_stamp());
    if (!fifo->pop(e, now)) {
      activity_ = Activity::waiting_for_ray;
      wait(fifo->pushed_event());
      continue;
    }
    activity_ = Activity::tracing;
    take(e, cycle_of(std::max(now, e.avail)));
  }
}

// Answers leave in the order they are ready (rays finish out of order), each when it is
// ready: the bus sees them at their times. A ray's slot is free once the bus has its answer.
template <typename T>
void IntersectionUnit<T>::write_back() {
  for (;;) {
    if (answers_.empty()) {
      wait(answer_queued_);
      continue;
    }
    const Answer a = answers_.top();
    const sc_time at = time_of(a.done);
    if (at > sc_time_stamp()) {
      wait(at - sc_time_stamp(), answer_queued_);  // an answer ready earlier may be queued meanwhile
      continue;
    }
    answers_.pop();
    sc_time delay = SC_ZERO_TIME;
    send_answer(a.ray, frame_.find(a.ray, static_cast<std::uint32_t>(id_)), delay);
    if (delay != SC_ZERO_TIME) wait(delay);  // a decoupled bus reports the transfer's end
    pipe_->retire(a.handle, a.done, cycle_of(sc_time_stamp()));
    slot_freed_.notify();
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
    case Activity::waiting_for_slot:
      return "pipelined: every ray slot holds a ray whose answer has not left (" + std::to_string(answers_.size()) +
             " answers queued); " + its_fifo;
  }
  return its_fifo;
}

template class IntersectionUnit<float>;
template class IntersectionUnit<double>;

}  // namespace oprt::hw
