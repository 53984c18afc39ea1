#include "hw/object_memory.h"

#include "hw/payloads.h"

namespace oprt::hw {

using namespace sc_core;

ObjectMemory::ObjectMemory(const sc_module_name& name, const Arch& arch, std::size_t spheres)
    : sc_module(name),
      read("read"),
      load("load"),
      latency_(arch.memory.model == MemoryModel::latency ? arch.cycle_ns() * arch.memory.latency_cycles : 0,
               SC_NS),
      loaded_(spheres, 0) {
  read.register_b_transport(this, &ObjectMemory::read_transport);
  load.register_b_transport(this, &ObjectMemory::load_transport);
}

void ObjectMemory::read_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  const auto* r = reinterpret_cast<const MemoryReadPacket*>(p.get_data_ptr());
  const bool whole_ray = r->sphere == kNone;  // a ray's reads over all its entered spheres
  if (p.get_command() != tlm::TLM_READ_COMMAND || (!whole_ray && (r->sphere >= loaded_.size() || !loaded_[r->sphere]))) {
    // The unit asked for geometry this memory does not hold: a wiring or assignment bug.
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  ++bursts_;
  bytes_read_ += p.get_data_length();
  delay += latency_;
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

void ObjectMemory::load_transport(tlm::tlm_generic_payload& p, sc_time&) {
  if (p.get_command() != tlm::TLM_WRITE_COMMAND) {
    p.set_response_status(tlm::TLM_COMMAND_ERROR_RESPONSE);
    return;
  }
  const auto* l = reinterpret_cast<const MemoryLoadPacket*>(p.get_data_ptr());
  std::fill(loaded_.begin(), loaded_.end(), 0);
  loaded_count_ = 0;
  for (std::uint32_t s : l->spheres) {
    if (s >= loaded_.size()) {
      p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
      return;
    }
    loaded_[s] = 1;
    ++loaded_count_;
  }
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

}  // namespace oprt::hw
