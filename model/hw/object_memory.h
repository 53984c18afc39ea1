// ObjectMemory: the geometry store beside one intersection unit, holding the triangles (and
// BVH nodes) of the spheres assigned to it. Loaded over the bus (`load`), read by its unit
// (`read`), one transaction per sphere visit (or per ray, when nothing times the visits).
//
// Its timing is the plain-C++ model every level shares (timing/object_memory_model.h):
// on-chip memory (ideal, or latency and streaming), or, when the unit's spheres exceed
// memory.sram_bytes, a cache in front of DRAM. A read that carries a visit's bursts
// (VisitReadExtension) is timed by the model, which hands each burst's arrivals to the
// unit's consumer; a plain read takes no time of its own (the functional trace holds
// on-chip memory's, memory_timing.h). A cache keeps its lines from frame to frame. Its DRAM
// channel is its own, inside the model; a channel shared with other units, misses over
// the shared bus, or misses out of the engine (memory.dram.path "external") go out through
// `fill` (hw/dram.h). The VCD counts its misses in flight.
#pragma once

#include "arch/arch.h"
#include "hw/extensions.h"
#include "timing/object_memory_model.h"
#include "trace/vcd_writer.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

namespace oprt::hw {

using timing::CacheCounts, timing::Cycle, timing::ObjectMemoryModel;

class ObjectMemory : public sc_core::sc_module, private ObjectMemoryModel::Fill {
 public:
  tlm_utils::simple_target_socket<ObjectMemory> read;     // from its unit
  tlm_utils::simple_target_socket<ObjectMemory> load;     // from the bus
  // Cache misses to a shared DRAM channel (over the bus, or out of the engine); unbound when
  // its channel is its own.
  tlm_utils::simple_initiator_socket_optional<ObjectMemory> fill;

  ObjectMemory(const sc_core::sc_module_name& name, int unit, const Arch& arch, std::size_t spheres_in_scene,
               VcdWriter* vcd);

  std::uint64_t bytes_read() const { return bytes_read_; }
  bool is_cache() const { return model_.is_cache(); }
  const CacheCounts& cache_counts() const { return model_.counts(); }
  void reset_stats() {
    bytes_read_ = 0;
    model_.reset_counts();
  }
  std::size_t spheres_loaded() const { return loaded_count_; }

 private:
  void read_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void load_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  Cycle fetch(std::uint64_t address, Cycle t) override;  // Fill
  Cycle cycles(const sc_core::sc_time& t) const { return static_cast<Cycle>(t.value() / cycle_.value()); }
  sc_core::sc_time at(Cycle c) const { return sc_core::sc_time::from_value(static_cast<std::uint64_t>(c) * cycle_.value()); }

  const int unit_;
  const sc_core::sc_time cycle_;
  ObjectMemoryModel model_;
  const std::uint64_t fill_base_;  // DRAM's address where fills go: on the bus or out of the engine, its window
  std::vector<char> loaded_;  // per sphere of the scene
  std::size_t loaded_count_ = 0;
  std::uint64_t bytes_read_ = 0;
  bool sync_ = false;  // the read being timed waits until each miss is due
  tlm::tlm_generic_payload fill_;
  ByteBuffer line_;
  VcdWriter* vcd_;
  int vcd_misses_ = -1;
};

}  // namespace oprt::hw
