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

// The counts (not the times) of frame f on `units` units. A ray's bytes are what the recipe
// writes for each of its waves (ray_writes, gpp_recipe.h).
template <typename T>
void count_ray_figures(const FunctionalFrame<T>& f, const Arch& a, std::size_t units, RayFigures& out) {
  struct Wave {
    const std::uint32_t *first = nullptr, *last = nullptr;  // null: every unit (broadcast)
  };
  const auto bytes_of = [&](const Wave& w) {
    const RayWrites writes = ray_writes<T>(a, units, w);
    return writes.transfers * writes.bytes;
  };
  for (KindFigures& k : out.kind) k = KindFigures{};
  out.by_depth.clear();
  for (std::uint32_t id = 0; id < f.ray_count(); ++id) {
    const RayRecord<T>& r = f.rays[id];
    const int k = static_cast<int>(r.kind);
    KindFigures& kf = out.kind[k];
    ++kf.rays;
    if (r.depth >= out.by_depth.size()) out.by_depth.resize(r.depth + 1u, {});
    ++out.by_depth[r.depth][k];
    std::uint64_t writes = units;
    if (f.routed) {
      const auto [first, last] = f.route_of(id);
      writes = static_cast<std::uint64_t>(last - first);
      for (const std::uint32_t* p = first; p != last;) {  // wave by wave, the last flagged kWaveEnd
        const std::uint32_t* end = p;
        while (!(*end++ & kWaveEnd)) {
        }
        kf.ray_bytes += bytes_of({p, end});
        p = end;
      }
    } else {
      kf.ray_bytes += bytes_of({});
    }
    kf.unit_writes += writes;
    kf.answer_bytes += writes * answer_bytes<T>(r.kind);
  }
}

}  // namespace oprt::timing
