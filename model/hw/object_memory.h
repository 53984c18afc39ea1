// ObjectMemory: the geometry store beside one intersection unit, holding the triangle blocks
// of the spheres assigned to it. Loaded over the bus (`load`), read by its unit (`read`),
// one burst per sphere visit.
//
// Timing. `ideal`: data is there when the unit needs it. `latency`: a burst's first
// triangle arrives latency_cycles after the request, then the block streams at
// bytes_per_cycle. The unit requests the block when the sphere test hits, so the transform
// hides up to its own length of latency, and each triangle test starts when both the unit
// and that triangle's data are ready (stream_stall()).
#pragma once

#include "hw/arch.h"
#include "hw/memory_timing.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_target_socket.h>

namespace oprt::hw {

class ObjectMemory : public sc_core::sc_module {
 public:
  tlm_utils::simple_target_socket<ObjectMemory> read;  // from its unit
  tlm_utils::simple_target_socket<ObjectMemory> load;  // from the bus

  ObjectMemory(const sc_core::sc_module_name& name, const Arch& arch, std::size_t spheres_in_scene);

  std::uint64_t bytes_read() const { return bytes_read_; }
  std::uint64_t bursts() const { return bursts_; }
  void reset_stats() { bytes_read_ = bursts_ = 0; }
  std::size_t spheres_loaded() const { return loaded_count_; }

 private:
  void read_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void load_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);

  const sc_core::sc_time latency_;
  std::vector<char> loaded_;  // per sphere of the scene
  std::size_t loaded_count_ = 0;
  std::uint64_t bytes_read_ = 0, bursts_ = 0;
};

}  // namespace oprt::hw
