#include "analytic/units.h"

#include "timing/gpp_recipe.h"

#include <algorithm>

namespace oprt::analytic {

using timing::UnitState, timing::answer_bytes, timing::cached_visit, timing::serial_ray;

template <typename T>
AnalyticUnits<T>::AnalyticUnits(const FunctionalFrame<T>& f, const SceneGeometry<T>& g,
                                const std::vector<IuRegisters<T>>& regs, const Arch& a, Parts parts, AnalyticBus& bus,
                                AnalyticFifos& fifos, AnswerSink& gpp)
    : f_(f),
      regs_(regs),
      arch_(a),
      parts_(parts),
      bus_(bus),
      fifos_(fifos),
      gpp_(gpp),
      pipelined_(a.iu.model == IuModel::pipelined),
      transform_(a.kernel_costs().transform),
      free_(regs.size(), 0),
      miss_cycles_(regs.size()),
      waiting_(regs.size()),
      addresses_(g),
      rays_(g, a) {
  const std::size_t units = regs.size();
  cached_.reserve(units);
  for (std::uint32_t u = 0; u < units; ++u) {
    miss_cycles_[u] = f.cycles(nullptr, u);
    cached_.push_back({g, regs[u], addresses_, a, {}, 0});
  }
}

template <typename T>
void AnalyticUnits<T>::arrive(std::uint32_t u, std::uint32_t id, Cycles avail) {
  fifos_.pushed(u);
  if (pipelined_) return take_pipelined(u, id, avail);
  if (bus_.shared() && (bus_.unit_waits(u) || !waiting_[u].empty())) waiting_[u].push_back({id, avail});
  else start_serial(u, id, avail);
}

template <typename T>
typename AnalyticUnits<T>::Cycles AnalyticUnits<T>::arrive_everywhere(std::uint32_t id, Cycles avail) {
  const auto units = static_cast<std::uint32_t>(free_.size());
  bus_.count(units, answer_bytes<T>(f_.rays[id].kind));  // the answers: an ideal bus takes no time
  Cycles done_all = 0;
  for (std::uint32_t u = 0; u < units; ++u) {
    const Cycles start = std::max(free_[u], avail);
    const UnitRayWork* w = f_.find(id, u);
    const Cycles done = start + (w ? w->cycles : miss_cycles_[u]);
    free_[u] = done;
    fifos_.pushed(u);
    fifos_.popped(u, avail, start);
    done_all = std::max(done_all, done);
  }
  return done_all;
}

// On-chip memory: the trace holds the ray's cycles. Through a cache: visit by visit.
template <typename T>
typename AnalyticUnits<T>::Cycles AnalyticUnits<T>::serial_end(std::uint32_t u, std::uint32_t id,
                                                               const UnitRayWork* w, Cycles start) {
  if (!parts_.timed[u].cache) return start + f_.cycles(w, u);
  ObjectMemoryModel& memory = *parts_.memories[u];
  memory.forget_before(static_cast<Cycle>(start));
  reader_.memory = &memory;
  auto read = [&](const VisitStream& s, Cycle r, BurstConsumer& c) { return reader_.read(s, r, c); };
  auto no_state = [](UnitState, Cycle) {};
  auto visit = [&](const VisitWork& v, Cycle t) { return cached_visit(cached_[u], f_.rays[id], v, t, read, no_state); };
  auto no_phase = [](UnitState, Cycle, Cycle) {};
  return static_cast<Cycles>(serial_ray(f_, u, w, static_cast<Cycle>(start), transform_, true, visit, no_phase));
}

// A serial unit starts ray `id` (arrived at `avail`) when it is free: its time on it, then its
// answer (at once on an ideal bus; granted in order on a shared one).
template <typename T>
void AnalyticUnits<T>::start_serial(std::uint32_t u, std::uint32_t id, Cycles avail) {
  const Cycles start = std::max(free_[u], avail);
  const Cycles end = serial_end(u, id, f_.find(id, u), start);
  fifos_.popped(u, avail, start);
  answer(u, id, end, 0);
}

template <typename T>
void AnalyticUnits<T>::take_pipelined(std::uint32_t u, std::uint32_t id, Cycles avail) {
  PipelinedUnitTiming& p = parts_.pipes[u];
  reader_.memory = parts_.memories[u].get();
  // Its slots free as its answers leave: those that leave by the time it could take the ray.
  Cycles start;
  for (;;) {
    start = std::max(static_cast<Cycles>(p.ready()), avail);
    if (!bus_.unit_waits(u) || bus_.unit_next_request(u) > start) break;
    grant_unit_until(u, bus_.unit_next_request(u));
  }
  parts_.memories[u]->forget_before(static_cast<Cycle>(start));
  const auto k = p.take(static_cast<Cycle>(start), static_cast<Cycle>(avail), rays_.build(f_, u, f_.find(id, u), id, regs_[u]),
                        reader_);
  fifos_.popped(u, avail, start);
  answer(u, id, static_cast<Cycles>(k.done), k.handle);
}

// The unit's answer to ray `id`, ready at `ready`: to the bus.
template <typename T>
void AnalyticUnits<T>::answer(std::uint32_t u, std::uint32_t id, Cycles ready, PipelinedUnitTiming::Handle h) {
  const std::uint64_t bytes = answer_bytes<T>(f_.rays[id].kind);
  if (bus_.shared()) return bus_.request(u, id, ready, bytes, h);
  granted({ready, 0, u, id, bytes, h}, bus_.transfer(ready, bytes));
}

template <typename T>
void AnalyticUnits<T>::granted(const AnalyticBus::Answer& a, Cycles done) {
  if (pipelined_) {
    parts_.pipes[a.unit].retire(a.handle, static_cast<Cycle>(a.at), static_cast<Cycle>(done));
  } else {
    parts_.timed[a.unit].bus_stall += done - a.at;
    free_[a.unit] = done;
  }
  gpp_.answered(a.ray, done);
  if (!pipelined_ && !waiting_[a.unit].empty()) {  // the next ray in its FIFO
    const Waiting w = waiting_[a.unit].front();
    waiting_[a.unit].pop_front();
    start_serial(a.unit, w.ray, w.avail);
  }
}

// Unit u's answers requested at or before t (and, first, everything requested before them).
template <typename T>
void AnalyticUnits<T>::grant_unit_until(std::uint32_t u, Cycles t) {
  while (bus_.unit_waits(u) && bus_.unit_next_request(u) <= t)
    bus_.grant_until(bus_.unit_next_request(u), [&](const AnalyticBus::Answer& a, Cycles done) { granted(a, done); });
}

template class AnalyticUnits<float>;
template class AnalyticUnits<double>;

}  // namespace oprt::analytic
