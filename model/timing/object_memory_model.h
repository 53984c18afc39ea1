// One unit's object memory as a timing model: when each item a visit reads is there. Plain
// C++, the one place this is decided: the SystemC object memory (hw/object_memory.cpp) owns
// one, the analytic level owns one per unit, and both serial and pipelined units read
// through it (timing/serial_unit_timing.h, timing/pipeline_timing.h).
//
// A visit reads bursts (VisitStream, cache.h: brute force one burst of the sphere's tested
// triangles; with a BVH each node a burst of one and each leaf a burst of its tested
// triangles). A burst is requested at a time the unit decides (a consumer, below: the first
// when the sphere test hits or the transform starts, a dependent one when the unit is done
// with the burst before); every item of it then has an arrival time:
//  - on-chip memory, `memory.model` ideal: at the request;
//  - `latency`: the memory's port streams one burst at a time; a burst requested at r
//    starts streaming at the first time s >= r + latency_cycles the port is free, and item
//    j (0-based) arrives at s + ceil((j + 1) bytes / bytes_per_cycle). A serial unit never
//    has two bursts in flight, so for it s = r + latency (memory_timing.h's formula);
//  - a cache (memory.sram_bytes too small for the unit's spheres, cache.h): every line of
//    the burst is looked up at the request; a hit is there as in on-chip memory, a line
//    still being filled when its fill arrives; a miss allocates the line and is sent to
//    DRAM when one of the unit's `misses_outstanding` miss registers is free (MissWindow).
//    DRAM: by default each object memory has a channel of its own, modelled here (a line
//    occupies it line_bytes / bytes_per_cycle cycles, first come first served, and arrives
//    latency_cycles after its transfer); channels shared by several units, or misses over
//    the shared bus, are another module's (the Fill the owner installs).
// The unit does not wait in here: it consumes each burst's arrivals (BurstConsumer) and
// says when it requests the next.
#pragma once

#include "arch/arch.h"
#include "timing/cache.h"
#include "timing/calendar.h"
#include "timing/cycle.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace oprt::timing {

// What the GPP writes into one object memory at a frame's start (timing/gpp_plan.h).
struct MemoryLoad {
  std::uint32_t unit = 0;
  std::uint64_t bytes = 0;   // geometry written (0 for a cache: DRAM holds it)
  bool cache = false;        // its spheres do not fit: the memory is a cache in front of DRAM
  const std::vector<std::uint32_t>* spheres = nullptr;
  // DRAM byte ranges rewritten this frame (deforming geometry): dropped from a cache.
  const std::vector<std::pair<std::uint64_t, std::uint64_t>>* rewritten = nullptr;
};

// What a unit does with a burst's items once they arrive.
class BurstConsumer {
 public:
  virtual ~BurstConsumer() = default;
  // Burst b of `v` (its items are the visit's items first .. first + n - 1) arrives item by
  // item at arrive[0 .. n). Returns when the unit requests the next burst (a dependent
  // fetch: when it is done with this one).
  virtual Cycle consume(const VisitStream& v, std::size_t b, std::size_t first, const Cycle* arrive) = 0;
};

// Misses go to a DRAM channel other units share, over the bus, or out of the engine
// (memory.dram.path "external"): another module's.
inline bool fills_leave_memory(const Arch& a) {
  return a.memory.dram.units_per_channel > 1 || a.memory.dram.path != DramPath::channel;
}

class ObjectMemoryModel {
 public:
  // A line fill from a DRAM channel the memory shares (or over the bus): sent at t, returns
  // the line's arrival.
  class Fill {
   public:
    virtual ~Fill() = default;
    virtual Cycle fetch(std::uint64_t address, Cycle t) = 0;
  };

  ObjectMemoryModel(const Arch& arch, std::uint32_t unit);

  // The frame's load (GppPlan::memory_loads): a memory that becomes a cache starts cold;
  // rewritten geometry is dropped.
  void load(const MemoryLoad& l);
  bool is_cache() const { return is_cache_; }
  std::uint32_t line_bytes() const { return cache_.line_bytes(); }
  // Shared DRAM (or the bus path): where misses go; null: the memory's own channel.
  void set_fill(Fill* f) { fill_ = f; }
  // Time restarts at 0 (the analytic level, each frame): every fill has arrived.
  void restart_time();

  // No request will come for a time before t (the unit's clock, or a pipeline's take).
  void forget_before(Cycle t);
  // Times the visit's bursts for `unit`; burst 0 requested at `request`. Returns the last
  // consume()'s result.
  Cycle visit(const VisitStream& v, Cycle request, BurstConsumer& unit);

  const CacheCounts& counts() const { return counts_; }
  void reset_counts() { counts_ = CacheCounts{}; }

 private:
  Cycle fetch(std::uint64_t line, Cycle t);

  const Arch& arch_;
  const std::uint32_t unit_;
  const bool latency_;
  const Cycle latency_cycles_, bytes_per_cycle_;
  bool is_cache_ = false;
  Cache cache_;
  MissWindow window_;
  // A serial unit's requests come in time order: its port and channel are then free after
  // their last grant (what a calendar reduces to in that case); a pipelined unit's come in
  // the order it places its rays' reads, and fill the calendars' gaps.
  const bool in_order_;
  Calendar<Cycle> port_;     // on-chip streaming (latency model)
  Calendar<Cycle> channel_;  // its own DRAM channel
  Cycle port_free_ = 0, channel_free_ = 0;
  const Cycle line_transfer_, dram_latency_;
  Fill* fill_ = nullptr;
  CacheCounts counts_;
  std::vector<Cycle> arrive_, line_ready_;  // scratch: one burst's items' and lines' arrivals
};

}  // namespace oprt::timing
