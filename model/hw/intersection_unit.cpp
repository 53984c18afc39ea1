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
                                      const FunctionalFrame<T>& frame, VcdWriter* vcd)
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
      clock_(unit_clock(arch)),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      vcd_(vcd) {
  cfg.register_b_transport(this, &IntersectionUnit::cfg_transport);
  if (arch.iu.model == IuModel::pipelined) {
    if (vcd_) pipe_trace_ = std::make_unique<Trace>(*vcd_, this->name(), cycle_.value());
    pipe_ = std::make_unique<PipelinedUnitTiming>(pipeline_config(arch, triangle_bytes_), pipe_trace_.get());
    reset_stats();
    SC_THREAD(run_pipelined);
    if (arch.bus.model != BusModel::ideal) SC_THREAD(write_back);
    return;
  }
  if (vcd_) vcd_state_ = vcd_->add(this->name(), "state", 3);
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
  if (pipe_) {  // the stages work side by side: each one's issue cycles, and the unit's stalls
    const PipelineStats& p = pipe_->stats();
    stats_.pipeline = p;
    stats_.cycles.sphere = p.stage[0].busy;
    stats_.cycles.transform = p.stage[1].busy;
    stats_.cycles.primitive = p.stage[2].busy;
    stats_.cycles.stall = p.stage[2].memory + p.answer_wait;
  }
  return stats_;
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
void IntersectionUnit<T>::trace_phases(const UnitRayWork* w, sc_time at) {
  const std::uint32_t transform = arch_.kernel_costs().transform;
  for_each_phase(frame_, w, static_cast<std::uint32_t>(id_), transform, [&](std::uint8_t state, std::uint64_t cycles) {
    trace_state(static_cast<UnitState>(state), at);
    at += cycle_ * static_cast<double>(cycles);
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
    if (vcd_) trace_phases(w, clock_.now());
    const UnitCycles c = frame_.breakdown(w, unit);
    ++stats_.rays[kind];
    clock_.advance(cycle_ * static_cast<double>(c.busy() + c.stall));
    stats_.cycles += c;

    // Answer the GPP. The unit waits for its transfer: time on the bus is a stall.
    const sc_time before = clock_.now();
    if (vcd_ && arch_.bus.model == BusModel::shared) trace_state(UnitState::stall, before);
    if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
    sc_time delay = clock_.offset();
    const sc_time sim = sc_time_stamp();
    activity_ = Activity::answering;
    send_answer(e.ray, w, delay);
    clock_.advance_to(sim + delay);  // decoupled: the transfer's end; at: already waited
    if (arch_.bus.model == BusModel::shared)
      stats_.cycles.stall += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
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
  const VisitWork* visits = nullptr;
  std::uint32_t n = 0;
  if (w) {
    visits = &frame_.units[unit].visits[w->first_visit];
    n = w->visits;
    for (std::uint32_t i = 0; i < n; ++i) read_memory(visits[i]);
  }
  const std::uint32_t tests = w ? w->sphere_tests : frame_.unit_entries[unit];
  const PipelinedUnitTiming::Taken k = pipe_->take(t, cycle_of(e.avail), tests, visits, n);
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
