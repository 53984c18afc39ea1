#include "hw/pipelined_unit.h"

namespace oprt::hw {

using timing::PipeStage, timing::PipelineConfig, timing::PipelineRay, timing::PipelineTrace, timing::kPipeStages,
    timing::pipeline_config, timing::to_string;

using namespace sc_core;

// A pipelined unit's waveform and timeline. Waveform: under the unit's `stage` scope (a
// signal group of its own), per unit in use whether it issues (`<unit>`: 1 in each issue
// slot) and how many operations wait for it (`<unit>_queue`), the rays waiting for object
// memory and the rays in flight. Timeline: a track per unit in use, one slice per issue
// slot (joined while they follow each other for one ray), named after the unit.
template <typename T>
class PipelinedUnit<T>::Trace : public PipelineTrace {
 public:
  Trace(VcdWriter* vcd, TimelineWriter* timeline, const std::string& unit, int id, const PipelineConfig& c,
        std::uint64_t cycle_ps)
      : vcd_(vcd), timeline_(timeline), cycle_(cycle_ps) {
    const std::string scope = unit + ".stage";
    for (int s = 0; s < kPipeStages; ++s) {
      if (!c.stage[s].used) continue;
      const std::string name = to_string(static_cast<PipeStage>(s));
      if (vcd_) {
        issue_[s] = vcd_->add_counter(scope, name, 1);
        queue_[s] = vcd_->add_counter(scope, name + "_queue", 16);
      }
      if (timeline_)
        track_[s] = timeline_->track(unit + "." + name, "stage", "IU " + std::to_string(id) + " " + name);
    }
    if (vcd_) {
      memory_ = vcd_->add_counter(scope, "memory_wait", 16);
      in_flight_ = vcd_->add_counter(scope, "rays_in_flight", 16);
    }
  }
  void issue(PipeStage s, Cycle start, Cycle end, std::uint32_t ray) override {
    const int i = static_cast<int>(s);
    if (vcd_) {
      vcd_->change_by(issue_[i], ps(start), 1);
      vcd_->change_by(issue_[i], ps(end), -1);
    }
    if (timeline_) timeline_->run_slice(track_[i], to_string(s), ps(start), ps(end), ray);
  }
  void waiting(PipeStage s, Cycle from, Cycle to) override { span(queue_[static_cast<int>(s)], from, to); }
  void memory(Cycle from, Cycle to) override { span(memory_, from, to); }
  void in_flight(Cycle t, int delta) override {
    if (vcd_) vcd_->change_by(in_flight_, ps(t), delta);
  }

 private:
  void span(int var, Cycle from, Cycle to) {
    if (!vcd_) return;
    vcd_->change_by(var, ps(from), 1);
    vcd_->change_by(var, ps(to), -1);
  }
  std::uint64_t ps(Cycle t) const { return static_cast<std::uint64_t>(t) * cycle_; }
  VcdWriter* vcd_;
  TimelineWriter* timeline_;
  std::uint64_t cycle_;
  int issue_[kPipeStages] = {}, queue_[kPipeStages] = {}, track_[kPipeStages] = {}, memory_ = -1, in_flight_ = -1;
};

template <typename T>
PipelinedUnit<T>::PipelinedUnit(const sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
                                const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline)
    : Base(name, id, arch, geometry, frame), mode_(unit_clock(arch)), rays_(geometry, arch) {
  const PipelineConfig config = pipeline_config(arch);
  if (vcd || timeline)
    trace_ = std::make_unique<Trace>(vcd, timeline, this->name(), id, config, this->cycle_.value());
  pipe_ = std::make_unique<PipelinedUnitTiming>(config, trace_.get());
  SC_THREAD(run);
  if (arch.bus.model != BusModel::ideal) SC_THREAD(write_back);
}

template <typename T>
PipelinedUnit<T>::~PipelinedUnit() = default;

template <typename T>
void PipelinedUnit<T>::reset_stats() {
  Base::reset_stats();
  pipe_->reset_stats();
}

template <typename T>
UnitStats& PipelinedUnit<T>::stats() {
  this->stats_.pipeline = pipe_->stats();
  return this->stats_;
}

// The pipeline's reads of one visit, through the memory socket.
template <typename T>
Cycle PipelinedUnit<T>::read(const VisitStream& s, Cycle request, BurstConsumer& unit) {
  return Base::read(s.sphere, s.bytes(), &s, &unit, request, false, taken_);
}

// The pipeline takes ray e at cycle t and places its program; the answer goes at once,
// annotated with its time, on an ideal bus, and through the write-back process otherwise.
template <typename T>
void PipelinedUnit<T>::take(const RayEntry& e, Cycle t) {
  const auto unit = static_cast<std::uint32_t>(this->id_);
  this->ray_ = e.ray;
  const UnitRayWork* w = this->frame_.find(e.ray, unit);
  const PipelineRay& ray = rays_.build(this->frame_, unit, w, e.ray, this->regs_);
  taken_ = t;  // its reads and every later ray's ask for nothing earlier
  const PipelinedUnitTiming::Taken k = pipe_->take(t, this->cycle_of(e.avail), ray, *this);
  ++this->stats_.rays[static_cast<int>(this->frame_.rays[e.ray].kind)];
  if (this->arch_.bus.model == BusModel::ideal) {
    pipe_->retire(k.handle, k.done, k.done);
    sc_time delay = this->time_of(k.done) - sc_time_stamp();
    this->send_answer(e.ray, w, delay);
    return;
  }
  answers_.push({k.done, e.ray, k.handle});
  answer_queued_.notify();
}

// How far ahead of simulation time the pipeline may take a ray: `ahead`, without limit;
// `quantum` (lt), up to the global quantum, as a decoupled serial unit runs; `exact`, not
// at all (the ray leaves its FIFO at the simulated time the pipeline takes it).
template <typename T>
void PipelinedUnit<T>::run() {
  for (;;) {
    const Cycle ready = pipe_->ready();
    if (ready == PipelinedUnitTiming::kNever) {  // every ray slot waits for its answer to leave
      this->activity_ = Base::Activity::waiting_for_slot;
      wait(slot_freed_);
      continue;
    }
    const sc_time at = this->time_of(ready);
    const sc_time lead = mode_ == LocalClock::Mode::ahead     ? sc_max_time()
                         : mode_ == LocalClock::Mode::quantum ? tlm_utils::tlm_quantumkeeper::get_global_quantum()
                                                              : SC_ZERO_TIME;
    if (at > sc_time_stamp() && at - sc_time_stamp() > lead) {
      this->activity_ = Base::Activity::tracing;
      wait(at - sc_time_stamp());
      continue;
    }
    RayEntry e;
    const sc_time now = std::max(at, sc_time_stamp());
    if (!this->fifo->pop(e, now)) {
      this->activity_ = Base::Activity::waiting_for_ray;
      wait(this->fifo->pushed_event());
      continue;
    }
    this->activity_ = Base::Activity::tracing;
    take(e, this->cycle_of(std::max(now, e.avail)));
  }
}

// Answers leave in the order they are ready (rays finish out of order), each when it is
// ready: the bus sees them at their times. A ray's slot is free once the bus has its answer.
template <typename T>
void PipelinedUnit<T>::write_back() {
  for (;;) {
    if (answers_.empty()) {
      wait(answer_queued_);
      continue;
    }
    const Answer a = answers_.top();
    const sc_time at = this->time_of(a.done);
    if (at > sc_time_stamp()) {
      wait(at - sc_time_stamp(), answer_queued_);  // an answer ready earlier may be queued meanwhile
      continue;
    }
    answers_.pop();
    sc_time delay = SC_ZERO_TIME;
    this->send_answer(a.ray, this->frame_.find(a.ray, static_cast<std::uint32_t>(this->id_)), delay);
    if (delay != SC_ZERO_TIME) wait(delay);  // a decoupled bus reports the transfer's end
    pipe_->retire(a.handle, a.done, this->cycle_of(sc_time_stamp()));
    slot_freed_.notify();
  }
}

template <typename T>
std::string PipelinedUnit<T>::waiting_for() const {
  if (this->activity_ == Base::Activity::waiting_for_slot)
    return "pipelined: every ray slot holds a ray whose answer has not left (" + std::to_string(answers_.size()) +
           " answers queued); " + this->its_fifo();
  return Base::waiting_for();
}

template class PipelinedUnit<float>;
template class PipelinedUnit<double>;

}  // namespace oprt::hw
