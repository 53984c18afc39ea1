// The analytic level: no SystemC process per ray. It follows the same plan and recipe as the
// SystemC GPP (timing/gpp_plan.h, gpp_recipe.h: the loads, the registers, the functional trace, the
// order of work, what each step costs and writes) and times the units with the same unit
// timing (timing/serial_unit_timing.h, pipeline_timing.h) and the same object memories
// (object_memory_model.h); only the way time passes differs: instead of events, a recurrence
// over the order in which rays enter the FIFOs, which is the order the GPP issues them. Its
// parts mirror the SystemC modules: analytic/gpp.h (hw/gpp.h), analytic/bus.h (hw/bus.h),
// analytic/ray_fifo.h (hw/ray_fifo.h), analytic/units.h (hw/serial_unit.h, pipelined_unit.h),
// analytic/dram.h (hw/dram.h). Not a SystemC module: plain C++, one call per frame.
#pragma once

#include "balance/assign.h"
#include "arch/arch.h"
#include "ref/functional_frame.h"
#include "timing/gpp_plan.h"
#include "timing/object_memory_model.h"
#include "analytic/ray_fifo.h"
#include "analytic/units.h"
#include "timing/pipeline_timing.h"
#include "timing/unit_run.h"
#include "scene/scene.h"

#include <memory>
#include <vector>

namespace oprt::analytic {

using timing::FrameCommand, timing::FrameRun, timing::GppPlan, timing::ObjectMemoryModel, timing::PipelinedUnitTiming,
    timing::UnitTimed;

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
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  GppPlan<T> plan_;
  FunctionalFrame<T> frame_;
  std::vector<std::unique_ptr<ObjectMemoryModel>> memories_;
  std::vector<PipelinedUnitTiming> pipes_;      // pipelined units
  std::vector<std::uint64_t> fifo_peak_;        // per unit, over the run
  void make_units(std::size_t units);
  void unit_figures(FrameRun& out, std::vector<UnitTimed>& timed, const AnalyticFifos& fifos,
                    const AnalyticUnits<T>& units);
};

extern template class AnalyticEngine<float>;
extern template class AnalyticEngine<double>;

}  // namespace oprt::analytic
