// The GPP's recipe, written once for both clocks: what each step of its work costs in GPP
// cycles and which transfers it causes (destination, bytes); what the bus and a DRAM channel
// charge for a transfer is in transfers.h. The SystemC modules (hw/gpp.cpp, bus.cpp, dram.cpp) and the
// analytic level (analytic/gpp.cpp, analytic/bus.h, analytic/dram.h) follow it; they only
// decide when time passes: a step calls its clock (gpp_clock.h), which is either the SystemC
// GPP (a local clock, transactions, waits) or the analytic GPP (a cycle count and calendars).
#pragma once

#include "arch/arch.h"
#include "ref/bytes.h"
#include "timing/gpp_clock.h"
#include "timing/transfers.h"
#include "timing/gpp_plan.h"

#include <cstdint>

namespace oprt::timing {

template <typename T, typename Wave>
RayWrites ray_writes(const Arch& a, std::size_t units, const Wave& wave) {
  RayWrites w;
  w.ray_bytes = w.bytes = Bytes<T>::ray_bytes(a.top_tree());
  if (!wave.first) return w;
  if (a.route.transfer == "mask") {
    w.kind = RayWrites::Kind::masked;
    w.bytes += (units + 7) / 8;
    return w;
  }
  w.kind = RayWrites::Kind::per_unit;
  w.transfers = static_cast<std::uint32_t>(wave.last - wave.first);
  return w;
}

// The answer a unit sends for a ray of this kind.
template <typename T>
constexpr std::uint64_t answer_bytes(RayKind k) {
  return seeks_nearest(k) ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer;
}

// The frame's start: the geometry that moved or deforms is written into object memory (the
// set-up loaded the rest), the units' trees are refitted, then every unit's registers are
// written. Returns the plan's configuration (its refit figures).
template <typename T, typename Clock>
const typename GppPlan<T>::Config& start_frame(GppPlan<T>& plan, const FrameCommand& cmd, Clock& clock) {
  static_assert(is_gpp_clock_v<Clock>, "start_frame's clock must have every member of a GPP clock (gpp_clock.h)");
  for (const MemoryLoad& l : plan.memory_loads()) clock.load(l);
  const auto& config = plan.configure(cmd);
  if (config.refit_cycles) clock.compute(GppPhase::refit, config.refit_cycles);
  for (std::size_t u = 0; u < plan.units(); ++u) clock.write_config(static_cast<std::uint32_t>(u), config.bytes[u]);
  return config;
}

// Write ray `id`'s next wave (every unit when broadcast): a new ray is generated
// (gpp.cycles_per_ray) and routed first (the router's cycles, gpp_plan.h); then the writes.
// Returns the number of units the wave goes to. The caller has waited for the FIFOs' room.
template <typename T, typename Time, typename Clock>
std::size_t issue_ray(const GppPlan<T>& plan, GppWork<T, Time>& work, std::uint32_t id, const Arch& a, Clock& clock) {
  static_assert(is_gpp_clock_v<Clock>, "issue_ray's clock must have every member of a GPP clock (gpp_clock.h)");
  const auto wave = work.wave(id);
  const std::size_t n = wave.size(plan.units());
  if (wave.initial) {
    if (a.gpp.cycles_per_ray) clock.compute(GppPhase::generate, static_cast<std::uint64_t>(a.gpp.cycles_per_ray));
    if (const std::uint64_t route = plan.route_cycles(work.entered(id))) clock.compute(GppPhase::route, route);
    clock.generated(id);
  }
  work.wrote(id);
  if (n == 0) clock.routed_nowhere(id);
  else clock.write_rays(id, wave, ray_writes<T>(a, plan.units(), wave));
  return n;
}

// Handle the completion due first: a routed ray's next wave is queued, or the ray retires; a
// ray that hit is shaded (gpp.cycles_per_hit) and the rays it spawns queued.
template <typename T, typename Time, typename Clock>
typename GppWork<T, Time>::Retired retire_ray(GppWork<T, Time>& work, const Arch& a, Clock& clock) {
  static_assert(is_gpp_clock_v<Clock>, "retire_ray's clock must have every member of a GPP clock (gpp_clock.h)");
  const auto r = work.retire();
  if (r.shade && a.gpp.cycles_per_hit) clock.compute(GppPhase::shade, static_cast<std::uint64_t>(a.gpp.cycles_per_hit));
  return r;
}

}  // namespace oprt::timing
