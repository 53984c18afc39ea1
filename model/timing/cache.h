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
// Timing: object_memory_model.h (when each line a visit reads is there) and the units'
// consumers of it (serial_unit_timing.h, pipeline_timing.h).
#pragma once

#include "arch/arch.h"
#include "ref/bvh_traverse.h"

#include <algorithm>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace oprt::timing {

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
  // A burst's lines [first, last], in order, in one step: each(line, slot, hit) for each, as
  // access() would give them (a hit is found in the set without a call; a miss allocates).
  template <typename Each>
  void access_lines(std::uint64_t first, std::uint64_t last, Each&& each) {
    for (std::uint64_t line = first; line <= last; ++line) {
      ++clock_;
      Way* set = &way_[(set_mask_ != kNoMask ? line & set_mask_ : line % sets_) * ways_];
      Way* held = nullptr;
      for (std::uint32_t w = 0; w < ways_ && !held; ++w)
        if (set[w].tag == line) held = &set[w];
      if (held) {
        if (replacement_ == CacheReplacement::lru) held->stamp = clock_;
        each(line, &held->ready, true);
      } else {
        each(line, allocate(set, line), false);
      }
    }
  }
  // Drop every line in [first, end) (geometry rewritten in DRAM: deforming objects).
  void invalidate(std::uint64_t first, std::uint64_t end);
  // Every fill has arrived (between frames, where the analytic level's time restarts at 0).
  void settle() {
    for (Way& w : way_) w.ready = 0;
  }

 private:
  struct Way;
  std::uint64_t* allocate(Way* set, std::uint64_t line);  // a miss: a way of the set for `line`
  struct Way {
    std::uint64_t tag = ~std::uint64_t{0};  // the line held; ~0: empty
    std::uint64_t ready = 0;
    std::uint64_t stamp = 0;  // lru: last use; fifo: fill
  };
  std::uint32_t line_bytes_ = 64, ways_ = 1;
  std::uint64_t sets_ = 1;
  static constexpr std::uint64_t kNoMask = ~std::uint64_t{0};
  std::uint64_t set_mask_ = kNoMask;  // sets - 1 when sets is a power of two
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
  void clear() {
    arrivals_.clear();
    head_ = 0;
  }
  void sent(std::uint64_t arrival) {
    if (head_ == arrivals_.size() || arrival >= arrivals_.back()) return arrivals_.push_back(arrival);
    arrivals_.insert(std::upper_bound(arrivals_.begin() + static_cast<std::ptrdiff_t>(head_), arrivals_.end(), arrival),
                     arrival);
  }

 private:
  void pop() {
    if (++head_ == arrivals_.size()) clear();
  }
  std::uint32_t limit_;
  std::vector<std::uint64_t> arrivals_;  // in flight, ascending, from head_ on
  std::size_t head_ = 0;
};

// What one visit reads, in memory order.
struct VisitStream {
  struct Burst {
    std::uint64_t address = 0;
    std::uint32_t items = 0, item_bytes = 0;
    bool node = false;  // a BVH node (box test), else triangles
  };
  std::uint32_t sphere = 0xFFFFFFFFu;   // whose geometry
  std::vector<std::uint8_t> stages;      // per item: a triangle's exit stage, or kLogNode
  std::vector<std::uint32_t> node_ids;   // BVH: nodes in walk order (scratch)
  std::vector<Burst> bursts;
  // A pipelined unit's traversal stack (pipeline_timing.h): per burst the spills and fills
  // before its request, and the visit's pushes, spills and fills.
  std::vector<std::uint8_t> stack_ops;
  std::uint32_t pushes = 0, spills = 0, fills = 0;
  std::uint64_t bytes() const {
    std::uint64_t b = 0;
    for (const Burst& x : bursts) b += std::uint64_t{x.items} * x.item_bytes;
    return b;
  }
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

}  // namespace oprt::timing
