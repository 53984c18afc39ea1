// The analytic level: no SystemC process per ray. Each unit's work on a ray comes from the
// same functional trace as at every other level (functional_frame.h, so busy cycles are
// identical by construction); time comes from a recurrence over the order in which rays
// enter the FIFOs, which is the order the GPP issues them:
//   a unit starts ray k at max(when it finished its previous ray, when ray k arrived),
//   a ray completes when its last answer arrives, and the GPP handles completions in
//   (time, ray) order with the same priorities as the SystemC GPP (answers, then pending
//   shadow rays, then the next primary ray), FIFO room and the shared bus's calendar.
// A unit's timing for a ray depends only on rays issued before it, so each ray is timed
// when it is issued. Under the paper's ideal architecture this is exactly the timing of
// `at`. With a shared bus it is approximate: a later-issued ray's answer may in truth take
// the bus before an earlier-issued one's, and the calendar grants in issue order instead.
// A pipelined unit (`"iu": {"model": "pipelined"}`) is timed by the same model as the
// SystemC unit's (pipeline_timing.h): it takes ray k at max(when the pipeline can take a
// ray, when ray k arrived), and its answer leaves when the bus has carried it.
// Not a SystemC module: plain C++, one call per frame.
#pragma once

#include "balance/assign.h"
#include "arch/arch.h"
#include "timing/calendar.h"
#include "timing/functional_frame.h"
#include "timing/bytes.h"
#include "timing/pipeline_timing.h"
#include "timing/unit_cycles.h"
#include "timing/visit_stream.h"
#include "scene/scene.h"

#include <optional>
#include <vector>

namespace oprt::hw {

// What one frame produced; the SystemC testbench fills the same from its modules.
struct UnitRun {
  UnitCycles cycles;
  std::uint64_t rays = 0;
  std::uint64_t memory_bytes = 0;
  std::uint64_t node_tests[kRayKinds] = {};  // --top bvh
  bool cache = false;  // its spheres did not fit its object memory (memory.sram_bytes)
  std::uint64_t assigned_bytes = 0;
  CacheCounts memory;  // through the cache; stall: the memory's, whichever it is
  std::uint64_t memory_load_bytes = 0;      // geometry loaded into its object memory this frame
  std::uint64_t fifo_pushes = 0, fifo_pops = 0;
  std::uint64_t fifo_peak = 0;              // most rays its FIFO held at once, over the run so far
  std::optional<PipelineStats> pipeline;    // a pipelined unit's stages
};

struct FrameRun {
  std::uint64_t makespan = 0;
  std::uint64_t rays[kRayKinds] = {};
  std::uint64_t bus_busy = 0, bus_bytes = 0, bus_transfers = 0, memory_load_bytes = 0;
  std::uint64_t memory_load_cycles = 0;  // bus time of the geometry moved in (0 on an ideal bus)
  std::uint64_t refit_nodes = 0, refit_cycles = 0, built_nodes = 0;  // --top bvh: the GPP's refit (gpp.h)
  std::vector<UnitRun> units;
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;  // [kind][sphere], whichever unit did it
};

template <typename T>
class AnalyticEngine {
 public:
  AnalyticEngine(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch)
      : scene_(scene), geom_(geometry), arch_(arch) {}
  void assign(const Assignment& a) { assignment_ = a.unit; }
  // Before the animation: object memories hold their units' geometry, or are caches in
  // front of DRAM where it does not fit (no time, no stats).
  void setup();
  // Renders cmd.image and returns the frame's timing.
  FrameRun run_frame(const FrameCommand& cmd);

 private:
  const Scene& scene_;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  std::vector<std::vector<std::uint32_t>> assignment_, loaded_;
  std::vector<TopTree> trees_;  // --top bvh: per unit
  // Object memories that are caches (memory.sram_bytes), kept from frame to frame.
  std::vector<char> cached_;
  std::vector<Cache> caches_;
  std::vector<MissWindow> windows_;
  void cold_cache(std::size_t u);
  FunctionalFrame<T> frame_;
  std::vector<PipelinedUnitTiming> pipes_;  // pipelined units
  std::vector<std::uint64_t> fifo_peak_;    // per unit, over the run
};

extern template class AnalyticEngine<float>;
extern template class AnalyticEngine<double>;

}  // namespace oprt::hw
