// What each kind of ray asks of the engine in a frame: how many, at which depth, how many
// units each was written to (its fan-out), the bytes of the rays written over the bus and of
// the answers sent back; and what the dependency of a spawned ray on its parent's answer
// costs in time (GppWork::Waiting, in cycles). The counts come from the frame's trace and the
// recipe's sizes (gpp_recipe.h), so they are the same at every level; the times from the
// level's GPP.
#pragma once

#include "arch/arch.h"
#include "ref/functional_frame.h"
#include "timing/gpp_recipe.h"
#include "timing/transfers.h"

#include <array>
#include <cstdint>
#include <vector>

namespace oprt::timing {

struct KindFigures {
  std::uint64_t rays = 0;
  std::uint64_t unit_writes = 0;   // (ray, unit) pairs: the rays' fan-out summed
  std::uint64_t ray_bytes = 0;     // written over the bus (a broadcast once, a masked wave once, else per unit)
  std::uint64_t answer_bytes = 0;  // the units' answers
  std::uint64_t latency = 0;       // cycles from each ray's issue to its last answer, summed
  std::uint64_t spawn_delay = 0;   // spawned rays: cycles from their parent's issue to their own, summed
};

struct RayFigures {
  std::array<KindFigures, kRayKinds> kind;
  std::vector<std::array<std::uint64_t, kRayKinds>> by_depth;  // [depth][kind]: rays
  std::uint64_t starved = 0;  // cycles the GPP had rays in flight and none it could issue
};

// Ray `id`'s traffic on `units` units: the units it was written to, the bytes of its writes
// (what the recipe writes for each of its waves: ray_writes, gpp_recipe.h) and of the units'
// answers, and the cycles they hold a shared bus (transfers.h; none on an ideal bus).
struct RayTraffic {
  std::uint64_t writes = 0, ray_bytes = 0, answer_bytes = 0, bus_cycles = 0;
};

template <typename T>
RayTraffic ray_traffic(const FunctionalFrame<T>& f, const Arch& a, std::size_t units, std::uint32_t id) {
  struct Wave {
    const std::uint32_t *first = nullptr, *last = nullptr;  // null: every unit (broadcast)
  };
  const bool shared = a.bus.model == BusModel::shared;
  RayTraffic t;
  const auto wave = [&](const Wave& w) {
    const RayWrites writes = ray_writes<T>(a, units, w);
    t.ray_bytes += writes.transfers * writes.bytes;
    if (shared) t.bus_cycles += writes.transfers * bus_occupancy(a, writes.bytes);
  };
  t.writes = units;
  if (f.routed) {
    const auto [first, last] = f.route_of(id);
    t.writes = static_cast<std::uint64_t>(last - first);
    for (const std::uint32_t* p = first; p != last;) {  // wave by wave, the last flagged kWaveEnd
      const std::uint32_t* end = p;
      while (!(*end++ & kWaveEnd)) {
      }
      wave({p, end});
      p = end;
    }
  } else {
    wave({});
  }
  const std::uint64_t answer = answer_bytes<T>(f.rays[id].kind);
  t.answer_bytes = t.writes * answer;
  if (shared) t.bus_cycles += t.writes * bus_occupancy(a, answer);
  return t;
}

// The counts (not the times) of frame f on `units` units.
template <typename T>
void count_ray_figures(const FunctionalFrame<T>& f, const Arch& a, std::size_t units, RayFigures& out) {
  for (KindFigures& k : out.kind) k = KindFigures{};
  out.by_depth.clear();
  for (std::uint32_t id = 0; id < f.ray_count(); ++id) {
    const RayRecord<T>& r = f.rays[id];
    const int k = static_cast<int>(r.kind);
    KindFigures& kf = out.kind[k];
    ++kf.rays;
    if (r.depth >= out.by_depth.size()) out.by_depth.resize(r.depth + 1u, {});
    ++out.by_depth[r.depth][k];
    const RayTraffic t = ray_traffic(f, a, units, id);
    kf.ray_bytes += t.ray_bytes;
    kf.unit_writes += t.writes;
    kf.answer_bytes += t.answer_bytes;
  }
}

}  // namespace oprt::timing
