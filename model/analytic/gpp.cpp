#include "analytic/gpp.h"

#include <algorithm>

namespace oprt::analytic {

using timing::issue_ray, timing::retire_ray;

template <typename T>
void AnalyticGpp<T>::connect(const FunctionalFrame<T>& f, AnalyticFifos& fifos, AnalyticUnits<T>& units,
                             AnalyticDram* dram) {
  f_ = &f;
  fifos_ = &fifos;
  units_ = &units;
  dram_ = dram;
  work_ = std::make_unique<GppWork<T, Cycles>>(f);
  answers_left_.assign(f.ray_count(), 0);
  ray_done_.assign(f.ray_count(), 0);
  simple_ = arch_.iu.model == IuModel::serial && !bus_.shared() && !plan_.any_cached();
}

template <typename T>
void AnalyticGpp<T>::compute(GppPhase phase, std::uint64_t cycles) {
  g_ += cycles;
  if (phase == GppPhase::route) out_.route.cycles += cycles;
}

// Geometry moved by an assignment change, and deforming geometry, is written into object
// memory inside the frame (the set-up loaded the rest).
template <typename T>
void AnalyticGpp<T>::load(const MemoryLoad& l) {
  on_load(l);
  out_.memory_load_bytes += l.bytes;
  const Cycles before = g_;
  g_ = bus_.transfer(g_, l.bytes);
  out_.memory_load_cycles += g_ - before;
}

template <typename T>
template <typename Wave>
void AnalyticGpp<T>::write_rays(std::uint32_t id, const Wave& wave, const RayWrites& w) {
  const auto units = static_cast<std::uint32_t>(plan_.units());
  answers_left_[id] = static_cast<std::uint32_t>(wave.size(units));
  if (bus_.shared()) grant_until(g_);  // answers requested before the GPP's write take the bus first
  // Every later request is at or after g (the GPP's time never decreases, and a unit answers
  // after the ray arrived): grants that ended by then can no longer matter.
  bus_.forget_before(g_);
  if (dram_) dram_->forget_before(g_);
  for (std::uint32_t i = 0; i < w.transfers; ++i) g_ = bus_.transfer(g_, w.bytes);
  if (!wave.first && simple_) return work_->answered(units_->arrive_everywhere(id, g_), id);
  if (!wave.first) {
    for (std::uint32_t u = 0; u < units; ++u) units_->arrive(u, id, g_);
    return;
  }
  for (const std::uint32_t* p = wave.first; p != wave.last; ++p) units_->arrive(*p & ~kWaveEnd, id, g_);
}

template <typename T>
void AnalyticGpp<T>::answered(std::uint32_t ray, Cycles done) {
  ray_done_[ray] = std::max(ray_done_[ray], done);
  if (--answers_left_[ray] == 0) work_->answered(ray_done_[ray], ray);
}

template <typename T>
void AnalyticGpp<T>::grant_until(Cycles t) {
  bus_.grant_until(t, [&](const AnalyticBus::Answer& a, Cycles done) { units_->granted(a, done); });
}

// When the FIFOs of the units the next write goes to have room (as the SystemC GPP reads it
// off its FIFOs); `unknown` while one of them has yet to pop the ray whose slot the write needs.
template <typename T>
typename AnalyticGpp<T>::Cycles AnalyticGpp<T>::room_time() const {
  Cycles t = g_;
  if (!fifos_->bounded()) return t;
  const auto wave = work_->wave(work_->peek_ray());
  if (!wave.first) {
    for (std::uint32_t u = 0; u < plan_.units(); ++u) t = std::max(t, fifos_->room(u));
  } else {
    for (const std::uint32_t* p = wave.first; p != wave.last; ++p) t = std::max(t, fifos_->room(*p & ~kWaveEnd));
  }
  return t;
}

// The GPP's work in its order (GppWork), as the SystemC GPP does it: a completion due, else
// the next ray once every FIFO has room, else wait for whichever comes first.
template <typename T>
typename AnalyticGpp<T>::Cycles AnalyticGpp<T>::run() {
  using Next = typename GppWork<T, Cycles>::Next;
  constexpr Cycles never = ~Cycles{0};
  for (;;) {
    grant_until(g_);
    const Cycles room = work_->has_ray() ? room_time() : never;
    if (room == AnalyticFifos::unknown) {  // a unit has yet to pop the ray whose slot the next one needs
      grant_until(bus_.next_request());
      continue;
    }
    const auto next = work_->next(g_, room, never, work_->due(never) == never && bus_.idle());
    if (next == Next::done) break;
    if (next == Next::retire) {
      retire_ray(*work_, arch_, *this);
    } else if (next == Next::issue) {
      issue_ray(plan_, *work_, work_->take_ray(g_), arch_, *this);
    } else {
      const Cycles t = std::min(work_->due(never), room);
      if (!bus_.idle() && bus_.next_request() <= t) grant_until(bus_.next_request());  // may complete a ray earlier
      else g_ = t;  // the GPP waits
    }
  }
  return g_;
}

template class AnalyticGpp<float>;
template class AnalyticGpp<double>;

}  // namespace oprt::analytic
