// What crosses the bus, and where it goes. Transactions are TLM-2.0 generic payloads whose
// data_length is the number of bytes the hardware would move; the data pointer carries the
// modelled contents as a typed record (the model keeps one copy where the hardware would
// keep several: a broadcast ray's contents live once in the RayStore, each FIFO keeps its
// id).
#pragma once

#include "timing/bytes.h"
#include "timing/cache.h"
#include "ref/image.h"
#include "ref/traverse.h"

#include <cstdint>
#include <vector>

namespace oprt::hw {

// Bus address map. Each unit i owns a window at iu_base + i * iu_stride.
namespace addr {
constexpr std::uint64_t gpp_hits = 0x0400'0000;        // answers from the units
constexpr std::uint64_t broadcast_rays = 0x0800'0000;  // a ray written here enters every FIFO
constexpr std::uint64_t dram = 0x0C00'0000;            // cache line fills (memory.dram.path "bus")
constexpr std::uint64_t region_size = 0x1000;
constexpr std::uint64_t iu_base = 0x1000'0000;
constexpr std::uint64_t iu_stride = 0x0100'0000;
constexpr std::uint64_t iu_config = 0x0000'0000;       // + configuration registers
constexpr std::uint64_t iu_memory = 0x0040'0000;       // + object memory load window
constexpr std::uint64_t iu_ray_fifo = 0x0080'0000;     // + this unit's ray FIFO only
constexpr std::uint64_t iu_window(int unit) { return iu_base + static_cast<std::uint64_t>(unit) * iu_stride; }
}  // namespace addr



template <typename T>
struct RayPacket {
  std::uint32_t id;
  const RayRecord<T>* record;
};

template <typename T>
struct AnswerPacket {
  std::uint32_t ray = 0;
  std::uint32_t unit = 0;
  bool occluded = false;  // shadow rays
  HitRecord<T> hit;       // primary rays
};

template <typename T>
struct ConfigPacket {
  const IuRegisters<T>* registers;
  bool cached = false;  // its object memory is a cache (its spheres do not fit): time visits through it
};


// Object memory contents: which spheres' triangle blocks are loaded.
struct MemoryLoadPacket {
  std::vector<std::uint32_t> spheres;
  bool cache = false;  // they do not fit: the memory is a cache in front of DRAM (cache.h)
  // Cache: DRAM byte ranges rewritten this frame (deforming geometry), to drop from it.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> rewritten;
};

// The reads of one sphere visit: its triangles (and, with a BVH, its nodes); sphere kNone:
// of all the spheres one ray entered.
struct MemoryReadPacket {
  std::uint32_t sphere;
  std::uint64_t bytes;
  // A cache times the visit: what it reads, and the unit's costs; the annotated delay is
  // the visit's start, and on return its end.
  const VisitStream* stream = nullptr;
  const VisitCosts* costs = nullptr;
  bool sync = false;   // wait until each miss is due before sending it (DRAM sees requests in time order)
  int state_var = -1;  // the unit's state signal in the VCD, for its stalls
  std::uint64_t stall = 0;  // out: the visit's stall cycles
};

// A cache line fill from DRAM.
struct MemoryFillPacket {
  std::uint32_t unit;
  std::uint64_t address;
};

}  // namespace oprt::hw
