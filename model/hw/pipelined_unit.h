// PipelinedUnit: the paper's future work, an intersection unit built of separate units (a
// node unit with --top bvh, a sphere unit, a transform unit, a box unit with --accel bvh, a
// triangle unit) with several rays in flight, each with its traversal stack. Its timing is
// timing/pipeline_timing.h's, which the analytic level calls too: the unit places a ray's
// whole program when it takes the ray, and reads each entered sphere through its object
// memory (the mem socket: the memory times the reads, cache or not, and the pipeline
// consumes them); answers leave out of ray order, each at its own time.
//
// Where nothing can observe the unit (`ahead`), it takes each ray as soon as the pipeline
// can. Otherwise (a bounded FIFO, a shared bus) it pops each ray at the simulated time the
// pipeline takes it. On an ideal bus an answer takes no time and meets no other transfer:
// it is sent at once, annotated with its time, and the GPP acts on it only then (gpp.cpp).
// On a shared bus a second process sends each answer when it is ready, in time order, and
// frees its ray slot when the bus has taken it.
//
// Its misses, if its memory is a cache on a shared DRAM channel, are granted by the
// channel's calendar in the order the unit places them (pipeline_timing.h places a ray's
// reads when it takes the ray, ahead of simulation time), not in time order as a serial
// unit's are at `at`.
#pragma once

#include "hw/intersection_unit.h"
#include "timing/pipeline_timing.h"
#include "trace/timeline.h"
#include "trace/vcd_writer.h"

#include <memory>
#include <queue>

namespace oprt::hw {

using timing::BurstConsumer, timing::Cycle, timing::PipelineRayBuilder, timing::PipelinedUnitTiming,
    timing::VisitReader, timing::VisitStream;

template <typename T>
class PipelinedUnit : public IntersectionUnit<T>, private VisitReader {
 public:
  SC_HAS_PROCESS(PipelinedUnit);
  PipelinedUnit(const sc_core::sc_module_name& name, int id, const Arch& arch, const SceneGeometry<T>& geometry,
                const FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline = nullptr);
  ~PipelinedUnit() override;

  UnitStats& stats() override;
  void reset_stats() override;
  sc_core::sc_time trace_floor() const override { return this->time_of(pipe_->trace_floor()); }
  std::string waiting_for() const override;

 private:
  using Base = IntersectionUnit<T>;
  class Trace;
  void run();         // the intake: pops rays
  void write_back();  // unless it runs ahead: sends answers in time order
  void take(const RayEntry& e, Cycle t);
  Cycle read(const VisitStream& s, Cycle request, BurstConsumer& unit) override;  // VisitReader

  struct Answer {
    Cycle done;
    std::uint32_t ray;
    PipelinedUnitTiming::Handle handle;
    bool operator>(const Answer& o) const { return done != o.done ? done > o.done : ray > o.ray; }
  };
  const LocalClock::Mode mode_;
  std::unique_ptr<Trace> trace_;
  std::unique_ptr<PipelinedUnitTiming> pipe_;
  PipelineRayBuilder<T> rays_;
  Cycle taken_ = 0;  // when the ray being placed was taken
  std::priority_queue<Answer, std::vector<Answer>, std::greater<Answer>> answers_;
  sc_core::sc_event answer_queued_, slot_freed_;
};

extern template class PipelinedUnit<float>;
extern template class PipelinedUnit<double>;

}  // namespace oprt::hw
