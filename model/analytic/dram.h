// The analytic level's DRAM (hw/dram.h), for memories whose misses contend: channels shared
// by several units (memory.dram.units_per_channel > 1), or misses over the shared bus. Each
// unit's misses reserve their channel's calendar (and the bus's) in the order the units' rays
// are timed (the SystemC DRAM grants them in time order instead). A line takes
// dram_line_cycles() of its channel (timing/gpp_recipe.h) and arrives latency_cycles after.
#pragma once

#include "arch/arch.h"
#include "analytic/bus.h"
#include "timing/calendar.h"
#include "timing/gpp_recipe.h"
#include "timing/object_memory_model.h"

#include <vector>

namespace oprt::analytic {

using timing::Cycle, timing::ObjectMemoryModel, timing::dram_line_cycles;  // Calendar: analytic/bus.h

class AnalyticDram {
 public:
  using Cycles = std::uint64_t;
  AnalyticDram(const Arch& a, std::size_t units, AnalyticBus& bus)
      : a_(a),
        per_channel_(static_cast<std::uint32_t>(a.memory.dram.units_per_channel)),
        channels_(units / per_channel_ + 1),
        fills_(units),
        bus_(bus),
        line_cycles_(dram_line_cycles(a)) {
    for (std::uint32_t u = 0; u < units; ++u) {
      fills_[u].d = this;
      fills_[u].unit = u;
    }
  }
  ObjectMemoryModel::Fill* fill(std::uint32_t u) { return &fills_[u]; }
  void forget_before(Cycles g) {
    for (auto& c : channels_) c.forget_before(g);
  }

 private:
  struct UnitFill final : ObjectMemoryModel::Fill {
    AnalyticDram* d = nullptr;
    std::uint32_t unit = 0;
    Cycle fetch(std::uint64_t, Cycle t) override { return d->fetch(unit, t); }
  };
  Cycle fetch(std::uint32_t u, Cycle t) {
    Cycles q = static_cast<Cycles>(t);
    if (a_.memory.dram.path == DramPath::bus) q = bus_.transfer(q, static_cast<std::uint64_t>(a_.memory.cache.line_bytes));
    return static_cast<Cycle>(channels_[u / per_channel_].reserve(q, line_cycles_) +
                              static_cast<Cycles>(a_.memory.dram.latency_cycles));
  }
  const Arch& a_;
  const std::uint32_t per_channel_;
  std::vector<Calendar<Cycles>> channels_;
  std::vector<UnitFill> fills_;
  AnalyticBus& bus_;
  const Cycles line_cycles_;
};

}  // namespace oprt::analytic
