// Object memory with a capacity (`--sram BYTES`, arch.h memory.sram_bytes): when a unit's
// assignment does not fit, its object memory becomes a cache in front of DRAM. Plain C++,
// shared by the SystemC object memory (object_memory.cpp) and the analytic level; times are
// cycles of the units' clock.
//
// Addresses. DRAM holds the whole scene's geometry once, as SceneGeometry lays it out: every
// triangle at index x triangle bytes (each sphere's triangles contiguous, in memory order),
// then every BVH node at node_base + index x node bytes. Addresses do not depend on the
// assignment, so a sphere that moves to another unit is simply read from there.
//
// What a visit reads, in memory order (VisitStream): brute force, one burst of the sphere's
// triangles from its first, as many as it tested (a shadow ray stops at its first occluder);
// with a BVH, each node fetched is a burst of one node and each leaf a burst of its tested
// triangles, in the order of the walk. The functional trace keeps counts, not addresses:
// the unit recomputes the visit's walk when it times it (visit_stream.h), which costs the
// visit's functional work a second time, only for units whose memory is a cache.
//
// Timing of a visit (time_visit), the latency model's (memory_timing.h) with lines: a burst
// is requested when the sphere test hits (the first) or when the previous test ends
// (dependent fetches), and every line it covers is looked up at that time. A hit is
// there as in on-chip memory (ideal: at once; latency: latency + the burst's streaming); a
// line still being filled by an earlier miss is there when that fill arrives. A miss
// allocates the line (evicting one of its set: lru, fifo or random) and asks DRAM for it
// (fetch), at most `misses_outstanding` at a time per unit: a further miss waits for the
// oldest to arrive. A test starts when the unit is free and every line of its item is
// there; the unit stalls otherwise.
#pragma once

#include "arch/arch.h"
#include "timing/memory_timing.h"
#include "ref/bvh_traverse.h"

#include <algorithm>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace oprt::hw {

// A set-associative tag store. Each line keeps the time its data is (or will be) there.
class Cache {
 public:
  Cache() = default;
  // capacity / (line_bytes x ways) sets (at least one); random replacement is seeded.
  Cache(std::uint64_t capacity, std::uint32_t line_bytes, std::uint32_t ways, CacheReplacement r, std::uint64_t seed);

  std::uint32_t line_bytes() const { return line_bytes_; }
  // Line `line` (address / line_bytes): its slot for the time its data is there, and whether
  // it was held. On a miss the line is allocated (a way of its set evicted) and the caller
  // writes the arrival of its fill into the slot. The slot is valid until the next access.
  std::uint64_t* access(std::uint64_t line, bool& hit);
  // Drop every line in [first, end) (geometry rewritten in DRAM: deforming objects).
  void invalidate(std::uint64_t first, std::uint64_t end);
  // Every fill has arrived (between frames, where the analytic level's time restarts at 0).
  void settle() {
    for (Way& w : way_) w.ready = 0;
  }

 private:
  struct Way {
    std::uint64_t tag = ~std::uint64_t{0};  // the line held; ~0: empty
    std::uint64_t ready = 0;
    std::uint64_t stamp = 0;  // lru: last use; fifo: fill
  };
  std::uint32_t line_bytes_ = 64, ways_ = 1;
  std::uint64_t sets_ = 1;
  CacheReplacement replacement_ = CacheReplacement::lru;
  std::vector<Way> way_;  // sets x ways
  std::uint64_t clock_ = 0, rng_ = 1;
};

// The misses of one unit in flight: at most `limit` at once.
class MissWindow {
 public:
  explicit MissWindow(std::uint32_t limit = 1) : limit_(limit) {}
  // When a miss wanted at `t` can be sent (a free slot); take the slot.
  std::uint64_t slot(std::uint64_t t);
  void clear() { arrivals_.clear(); }
  void sent(std::uint64_t arrival) { arrivals_.insert(std::upper_bound(arrivals_.begin(), arrivals_.end(), arrival), arrival); }

 private:
  std::uint32_t limit_;
  std::deque<std::uint64_t> arrivals_;  // in flight, ascending
};

// What one visit reads, in memory order.
struct VisitStream {
  struct Burst {
    std::uint64_t address = 0;
    std::uint32_t items = 0, item_bytes = 0;
    bool node = false;  // a BVH node (box test), else triangles
  };
  std::vector<std::uint8_t> stages;      // per item: a triangle's exit stage, or kLogNode
  std::vector<std::uint32_t> node_ids;   // BVH: nodes in walk order (scratch)
  std::vector<Burst> bursts;
};

struct CacheCounts {
  std::uint64_t hits = 0, misses = 0, dram_bytes = 0, stall = 0;
  CacheCounts& operator+=(const CacheCounts& o) {
    hits += o.hits;
    misses += o.misses;
    dram_bytes += o.dram_bytes;
    stall += o.stall;
    return *this;
  }
};

// How the unit works through a visit: StreamCosts (memory_timing.h) for the on-chip part,
// with `latency_model` false for an ideal on-chip memory.
struct VisitCosts {
  StreamCosts stream;
  bool latency_model = false;
};

// Times one visit that starts (its sphere test hit) at `start`. fetch(line, t) sends a
// miss at t and returns when the line arrives; state(code, t) reports what the unit does
// from t + lead on (UnitState codes: box 5, primitive 3, stall 4) for the waveform.
// Returns when the visit ends; its stall cycles are added to counts.
template <typename Fetch, typename State>
std::uint64_t time_visit(const VisitCosts& c, const VisitStream& v, std::uint64_t start, Cache& cache,
                         MissWindow& window, CacheCounts& counts, Fetch&& fetch, State&& state) {
  const StreamCosts& s = c.stream;
  const std::uint64_t line_bytes = cache.line_bytes();
  std::uint64_t t = start + s.lead, work = s.lead;
  std::size_t item = 0;
  int last_state = -1;
  auto report = [&](int code, std::uint64_t at) {
    if (code != last_state) state(code, at);
    last_state = code;
  };
  for (std::size_t b = 0; b < v.bursts.size(); ++b) {
    const VisitStream::Burst& burst = v.bursts[b];
    const std::uint64_t request = b == 0 ? start : t;
    std::uint64_t line = ~std::uint64_t{0}, line_ready = 0;  // the last line looked up
    for (std::uint32_t j = 0; j < burst.items; ++j, ++item) {
      const std::uint64_t address = burst.address + std::uint64_t{j} * burst.item_bytes;
      std::uint64_t arrive = request;
      if (c.latency_model)
        arrive += s.latency + ((j + 1) * std::uint64_t{burst.item_bytes} + s.bytes_per_cycle - 1) / s.bytes_per_cycle;
      const std::uint64_t last = (address + burst.item_bytes - 1) / line_bytes;
      for (std::uint64_t l = address / line_bytes; l <= last; ++l) {
        if (l == line) {
          arrive = std::max(arrive, line_ready);
          continue;
        }
        bool hit = false;
        std::uint64_t* slot = cache.access(l, hit);
        std::uint64_t ready;
        if (hit) {
          ++counts.hits;
          ready = std::max(*slot, request);
        } else {
          ++counts.misses;
          counts.dram_bytes += line_bytes;
          ready = fetch(l, window.slot(request));
          window.sent(ready);
          *slot = ready;
        }
        line = l;
        line_ready = ready;
        arrive = std::max(arrive, ready);
      }
      const std::uint8_t stage = v.stages[item];
      const bool node = stage == kLogNode;
      if (arrive > t) {
        report(4, t);
        t = arrive;
      }
      report(node ? 5 : 3, t);
      const std::uint64_t cost = node ? s.box : s.triangle[stage];
      t += cost;
      work += cost;
    }
  }
  counts.stall += t - start - work;
  return t;
}

}  // namespace oprt::hw
