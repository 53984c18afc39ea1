// The analytic level's intersection units (hw/serial_unit.cpp, pipelined_unit.cpp): the same
// unit timing (timing/serial_unit_timing.h, pipeline_timing.h) through the same object memories
// (object_memory_model.h), placed by a recurrence instead of events:
//  - a serial unit starts a ray at max(when it finished its previous ray, when the ray
//    arrived); on a shared bus it waits for its answer's grant, so a ray reaching it
//    meanwhile waits in its FIFO and starts when the answer is granted;
//  - a pipelined unit's slots free as its answers leave: it takes its next ray once the
//    answers that leave before it could have are granted (which may grant them before a
//    write the GPP makes later in its time but earlier than they: the level's error there).
// A unit's answer goes to the bus (analytic/bus.h); once it has left, the GPP is told
// (AnswerSink).
#pragma once

#include "arch/arch.h"
#include "analytic/bus.h"
#include "analytic/ray_fifo.h"
#include "ref/functional_frame.h"
#include "timing/object_memory_model.h"
#include "timing/pipeline_timing.h"
#include "timing/serial_unit_timing.h"
#include "timing/unit_run.h"

#include <deque>
#include <memory>
#include <vector>

namespace oprt::analytic {

using timing::BurstConsumer, timing::CachedVisits, timing::Cycle, timing::GeometryAddresses, timing::ObjectMemoryModel,
    timing::PipelineRayBuilder, timing::PipelinedUnitTiming, timing::UnitTimed, timing::VisitReader,
    timing::VisitStream, timing::Waiting;

// Where the units' answers go once the bus has taken them: the GPP.
class AnswerSink {
 public:
  virtual ~AnswerSink() = default;
  virtual void answered(std::uint32_t ray, std::uint64_t done) = 0;
};

template <typename T>
class AnalyticUnits {
 public:
  using Cycles = std::uint64_t;
  struct Parts {  // what the units are built of, owned by the engine across frames
    std::vector<std::unique_ptr<ObjectMemoryModel>>& memories;
    std::vector<PipelinedUnitTiming>& pipes;  // pipelined units
    std::vector<UnitTimed>& timed;
  };
  AnalyticUnits(const FunctionalFrame<T>& f, const SceneGeometry<T>& g, const std::vector<IuRegisters<T>>& regs,
                const Arch& a, Parts parts, AnalyticBus& bus, AnalyticFifos& fifos, AnswerSink& gpp);

  // Ray `id` reaches unit u's FIFO at `avail`.
  void arrive(std::uint32_t u, std::uint32_t id, Cycles avail);
  // Serial units, an ideal bus, on-chip memories, a broadcast ray: every unit takes it, and
  // the ray completes when the last one has answered (returned). Kept tight: most runs.
  Cycles arrive_everywhere(std::uint32_t id, Cycles avail);
  // The bus granted answer a, done at `done`.
  void granted(const AnalyticBus::Answer& a, Cycles done);
  std::uint64_t cache_stall(std::uint32_t u) const { return cached_[u].stall; }

 private:
  void start_serial(std::uint32_t u, std::uint32_t id, Cycles avail);
  void take_pipelined(std::uint32_t u, std::uint32_t id, Cycles avail);
  Cycles serial_end(std::uint32_t u, std::uint32_t id, const UnitRayWork* w, Cycles start);
  void answer(std::uint32_t u, std::uint32_t id, Cycles ready, PipelinedUnitTiming::Handle h);
  void grant_unit_until(std::uint32_t u, Cycles t);

  // Reads through a unit's own object memory model.
  struct DirectReader final : VisitReader {
    ObjectMemoryModel* memory = nullptr;
    Cycle read(const VisitStream& s, Cycle request, BurstConsumer& unit) override {
      return memory->visit(s, request, unit);
    }
  };
  struct Waiting {
    std::uint32_t ray;
    Cycles avail;
  };

  const FunctionalFrame<T>& f_;
  const std::vector<IuRegisters<T>>& regs_;
  const Arch& arch_;
  Parts parts_;
  AnalyticBus& bus_;
  AnalyticFifos& fifos_;
  AnswerSink& gpp_;
  const bool pipelined_;
  const Cycle transform_;
  std::vector<Cycles> free_;              // serial: when it finished its last ray (its answer granted)
  std::vector<Cycles> miss_cycles_;       // a ray that enters none of the unit's spheres
  std::vector<std::deque<Waiting>> waiting_;  // serial: rays in its FIFO while its answer waits
  const GeometryAddresses<T> addresses_;
  std::vector<CachedVisits<T>> cached_;   // rays through caches read their visits
  PipelineRayBuilder<T> rays_;
  DirectReader reader_;
};

extern template class AnalyticUnits<float>;
extern template class AnalyticUnits<double>;

}  // namespace oprt::analytic
