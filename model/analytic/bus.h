// The analytic level's bus (hw/bus.h): every transfer counted, and on a shared bus held
// bus_occupancy() cycles (timing/gpp_recipe.h), first come first served in a calendar. The units'
// answers wait here for it and are granted in the order of their requests, when the GPP's
// time passes them (before its own writes) or when the GPP waits: the SystemC bus grants
// them in request order because the units send them in time order.
#pragma once

#include "arch/arch.h"
#include "timing/calendar.h"
#include "timing/gpp_recipe.h"
#include "timing/pipeline_timing.h"
#include "timing/unit_run.h"

#include <cstdint>
#include <queue>
#include <set>
#include <vector>

namespace oprt::analytic {

using timing::Calendar, timing::FrameRun, timing::PipelinedUnitTiming, timing::bus_occupancy;

class AnalyticBus {
 public:
  using Cycles = std::uint64_t;
  // A unit's answer waiting for a shared bus.
  struct Answer {
    Cycles at;  // requested (when the unit finished the ray)
    std::uint64_t seq;
    std::uint32_t unit, ray;
    std::uint64_t bytes;
    PipelinedUnitTiming::Handle handle;  // pipelined: the ray's slot
    bool operator>(const Answer& o) const { return at != o.at ? at > o.at : seq > o.seq; }
  };

  AnalyticBus(const Arch& a, std::size_t units, FrameRun& counts)
      : arch_(a), shared_(a.bus.model == BusModel::shared), counts_(counts), unit_requests_(units) {}
  bool shared() const { return shared_; }

  // A transfer of `bytes` requested at `at`: returns when it is done.
  Cycles transfer(Cycles at, std::uint64_t bytes) {
    ++counts_.bus_transfers;
    counts_.bus_bytes += bytes;
    if (!shared_) return at;
    const Cycles occupancy = bus_occupancy(arch_, bytes);
    counts_.bus_busy += occupancy;
    return calendar_.reserve(at, occupancy);
  }
  // n transfers of `bytes` each on an ideal bus: counted, no time.
  void count(std::uint64_t n, std::uint64_t bytes) {
    counts_.bus_transfers += n;
    counts_.bus_bytes += n * bytes;
  }
  // Every later request is at or after t.
  void forget_before(Cycles t) { calendar_.forget_before(t); }

  void request(std::uint32_t unit, std::uint32_t ray, Cycles at, std::uint64_t bytes,
               PipelinedUnitTiming::Handle handle = 0) {
    waiting_.push({at, seq_++, unit, ray, bytes, handle});
    unit_requests_[unit].insert(at);
  }
  bool idle() const { return waiting_.empty(); }
  Cycles next_request() const { return waiting_.top().at; }
  // Unit u's earliest request, if it has one waiting.
  bool unit_waits(std::uint32_t u) const { return !unit_requests_[u].empty(); }
  Cycles unit_next_request(std::uint32_t u) const { return *unit_requests_[u].begin(); }

  // Grant every answer requested at or before t, in request order: granted(answer, done).
  template <typename Granted>
  void grant_until(Cycles t, Granted&& granted) {
    while (!waiting_.empty() && waiting_.top().at <= t) {
      const Answer a = waiting_.top();
      waiting_.pop();
      const Cycles done = transfer(a.at, a.bytes);
      unit_requests_[a.unit].erase(unit_requests_[a.unit].find(a.at));
      granted(a, done);
    }
  }

 private:
  const Arch& arch_;
  const bool shared_;
  FrameRun& counts_;
  Calendar<Cycles> calendar_;
  std::priority_queue<Answer, std::vector<Answer>, std::greater<Answer>> waiting_;
  std::vector<std::multiset<Cycles>> unit_requests_;  // per unit: its waiting answers' requests
  std::uint64_t seq_ = 0;
};

}  // namespace oprt::analytic
