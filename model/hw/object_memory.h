// ObjectMemory: the geometry store beside one intersection unit, holding the triangle blocks
// of the spheres assigned to it. Loaded over the bus (`load`), read by its unit (`read`),
// one burst per sphere visit.
//
// Timing. `ideal`: data is there when the unit needs it. `latency`: a burst's first
// triangle arrives latency_cycles after the request, then the block streams at
// bytes_per_cycle. The unit requests the block when the sphere test hits, so the transform
// hides up to its own length of latency, and each triangle test starts when both the unit
// and that triangle's data are ready (stream_stall()).
//
// With a capacity (memory.sram_bytes) that the unit's spheres exceed, the memory is a cache
// in front of DRAM (cache.h): the unit sends each visit's reads with their addresses, the
// memory times the visit line by line and sends its misses (`fill`) to the DRAM channel or
// over the bus. It keeps its lines from frame to frame. The VCD counts its misses in flight.
#pragma once

#include "arch/arch.h"
#include "timing/cache.h"
#include "timing/memory_timing.h"
#include "trace/vcd_writer.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

namespace oprt::hw {

class ObjectMemory : public sc_core::sc_module {
 public:
  tlm_utils::simple_target_socket<ObjectMemory> read;     // from its unit
  tlm_utils::simple_target_socket<ObjectMemory> load;     // from the bus
  // Cache misses, to DRAM; optional: a memory with no capacity limit never misses.
  tlm_utils::simple_initiator_socket_optional<ObjectMemory> fill;

  ObjectMemory(const sc_core::sc_module_name& name, int unit, const Arch& arch, std::size_t spheres_in_scene,
               VcdWriter* vcd);

  std::uint64_t bytes_read() const { return bytes_read_; }
  std::uint64_t bursts() const { return bursts_; }
  bool is_cache() const { return is_cache_; }
  const CacheCounts& cache_counts() const { return counts_; }
  void reset_stats() {
    bytes_read_ = bursts_ = 0;
    counts_ = CacheCounts{};
  }
  std::size_t spheres_loaded() const { return loaded_count_; }

 private:
  void read_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void load_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  std::uint64_t cycles(const sc_core::sc_time& t) const { return t.value() / cycle_.value(); }
  sc_core::sc_time at(std::uint64_t cycles) const { return sc_core::sc_time::from_value(cycles * cycle_.value()); }

  const int unit_;
  const Arch& arch_;
  const sc_core::sc_time cycle_, latency_;
  std::vector<char> loaded_;  // per sphere of the scene
  std::size_t loaded_count_ = 0;
  std::uint64_t bytes_read_ = 0, bursts_ = 0;
  bool is_cache_ = false;
  Cache cache_;
  MissWindow window_;
  CacheCounts counts_;
  tlm::tlm_generic_payload fill_;
  VcdWriter* vcd_;
  int vcd_misses_ = -1;
};

}  // namespace oprt::hw
