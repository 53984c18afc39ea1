// The analytic level's GPP (hw/gpp.cpp) for one frame: the plan's order of work (GppWork) and
// the recipe's steps (timing/gpp_recipe.h), timed by a cycle count instead of a local clock. It is
// the recipe's clock: it spends the GPP's cycles, writes through the bus (analytic/bus.h) to
// the units' FIFOs (analytic/ray_fifo.h, analytic/units.h) and collects their answers.
//   A unit's timing for a ray depends only on rays issued before it, so each ray is timed
// when it is issued. Under the paper's ideal architecture this is exactly the timing of
// `at`. With a shared bus it is approximate (analytic/bus.h, analytic/units.h).
#pragma once

#include "arch/arch.h"
#include "analytic/bus.h"
#include "analytic/dram.h"
#include "analytic/ray_fifo.h"
#include "analytic/units.h"
#include "timing/gpp_plan.h"
#include "timing/gpp_recipe.h"

#include <functional>
#include <memory>
#include <vector>

namespace oprt::analytic {

using timing::FrameRun, timing::GppPhase, timing::GppPlan, timing::GppWork, timing::MemoryLoad, timing::RayWrites,
    timing::Waiting;

template <typename T>
class AnalyticGpp final : public AnswerSink {
 public:
  using Cycles = std::uint64_t;
  AnalyticGpp(GppPlan<T>& plan, const Arch& a, FrameRun& out, AnalyticBus& bus)
      : plan_(plan), arch_(a), out_(out), bus_(bus) {}

  // Connect the frame's functional work and the units that time it (after start_frame).
  void connect(const FunctionalFrame<T>& f, AnalyticFifos& fifos, AnalyticUnits<T>& units, AnalyticDram* dram);
  // The GPP's work in its order until every ray has retired; returns the frame's makespan.
  Cycles run();
  Cycles now() const { return g_; }  // the GPP's time
  const Waiting<Cycles>& waiting() const { return work_->waiting(); }

  // The recipe's clock (timing/gpp_clock.h), called by its steps only (timing/gpp_recipe.h).
  void compute(GppPhase phase, std::uint64_t cycles);
  void load(const MemoryLoad& l);
  void write_config(std::uint32_t, std::uint64_t bytes) { g_ = bus_.transfer(g_, bytes); }
  void generated(std::uint32_t id) { ++out_.rays[static_cast<int>(f_->rays[id].kind)]; }
  void routed_nowhere(std::uint32_t id) { work_->answered(g_, id); }
  template <typename Wave>
  void write_rays(std::uint32_t id, const Wave& wave, const RayWrites& w);
  // An answer has left the bus (AnswerSink).
  void answered(std::uint32_t ray, Cycles done) override;

  // Set by the engine for the frame's loads (it owns the object memories).
  std::function<void(const MemoryLoad&)> on_load;

 private:
  Cycles room_time() const;
  void grant_until(Cycles t);

  GppPlan<T>& plan_;
  const Arch& arch_;
  FrameRun& out_;
  AnalyticBus& bus_;
  const FunctionalFrame<T>* f_ = nullptr;
  AnalyticFifos* fifos_ = nullptr;
  AnalyticUnits<T>* units_ = nullptr;
  AnalyticDram* dram_ = nullptr;
  std::unique_ptr<GppWork<T, Cycles>> work_;
  std::vector<std::uint32_t> answers_left_;
  std::vector<Cycles> ray_done_;
  bool simple_ = false;  // serial units, an ideal bus, on-chip memories
  Cycles g_ = 0;         // the GPP's time
};

extern template class AnalyticGpp<float>;
extern template class AnalyticGpp<double>;
static_assert(timing::is_gpp_clock_v<AnalyticGpp<float>> && timing::is_gpp_clock_v<AnalyticGpp<double>>,
              "the analytic GPP is the recipe's clock (timing/gpp_clock.h)");

}  // namespace oprt::analytic
