// The analytic level: no SystemC process per ray. It follows the same plan as the SystemC
// GPP (gpp_plan.h: the loads, the registers, the functional trace, the order of work) and
// times the units with the same unit timing (serial_unit_timing.h, pipeline_timing.h) and
// the same object memories (object_memory_model.h); only the way time passes differs:
// instead of events, a recurrence over the order in which rays enter the FIFOs, which is
// the order the GPP issues them:
//   a unit starts ray k at max(when it finished its previous ray, when ray k arrived),
//   a ray completes when its last answer arrives, and the GPP handles completions in
//   (time, ray) order with its priorities (answers, pending shadow rays, the next primary
//   ray), FIFO room and the shared bus's calendar.
// A unit's timing for a ray depends only on rays issued before it, so each ray is timed
// when it is issued. Under the paper's ideal architecture this is exactly the timing of
// `at`. With a shared bus it is approximate: a later-issued ray's answer may in truth take
// the bus before an earlier-issued one's, and the calendar grants in issue order instead;
// and the GPP decides to write a ray before it knows when the FIFOs have room (an answer
// due meanwhile waits). Not a SystemC module: plain C++, one call per frame.
#pragma once

#include "balance/assign.h"
#include "arch/arch.h"
#include "timing/functional_frame.h"
#include "timing/gpp_plan.h"
#include "timing/object_memory_model.h"
#include "timing/pipeline_timing.h"
#include "timing/unit_run.h"
#include "scene/scene.h"

#include <memory>
#include <vector>

namespace oprt::hw {

template <typename T>
class AnalyticEngine {
 public:
  AnalyticEngine(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch);
  ~AnalyticEngine();
  void assign(const Assignment& a);
  // Before the animation: object memories hold their units' geometry, or are caches in
  // front of DRAM where it does not fit (no time, no stats).
  void setup();
  // Renders cmd.image and returns the frame's timing.
  FrameRun run_frame(const FrameCommand& cmd);

 private:
  class SharedDram;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  GppPlan<T> plan_;
  FunctionalFrame<T> frame_;
  std::vector<std::unique_ptr<ObjectMemoryModel>> memories_;
  std::vector<PipelinedUnitTiming> pipes_;      // pipelined units
  std::vector<std::uint64_t> fifo_peak_;        // per unit, over the run
  void make_units(std::size_t units);
};

extern template class AnalyticEngine<float>;
extern template class AnalyticEngine<double>;

}  // namespace oprt::hw
