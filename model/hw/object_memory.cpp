#include "hw/object_memory.h"

#include "hw/payloads.h"

#include <algorithm>

namespace oprt::hw {

using namespace sc_core;

ObjectMemory::ObjectMemory(const sc_module_name& name, int unit, const Arch& arch, std::size_t spheres,
                           VcdWriter* vcd)
    : sc_module(name),
      read("read"),
      load("load"),
      fill("fill"),
      unit_(unit),
      arch_(arch),
      cycle_(arch.cycle_ns(), SC_NS),
      latency_(arch.memory.model == MemoryModel::latency ? arch.cycle_ns() * arch.memory.latency_cycles : 0,
               SC_NS),
      loaded_(spheres, 0),
      vcd_(vcd) {
  read.register_b_transport(this, &ObjectMemory::read_transport);
  load.register_b_transport(this, &ObjectMemory::load_transport);
  if (vcd_ && arch.memory.sram_bytes) vcd_misses_ = vcd_->add_counter(this->name(), "misses", 16);
}

void ObjectMemory::read_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  auto* r = reinterpret_cast<MemoryReadPacket*>(p.get_data_ptr());
  const bool whole_ray = r->sphere == kNone;  // a ray's reads over all its entered spheres
  if (p.get_command() != tlm::TLM_READ_COMMAND || (!whole_ray && (r->sphere >= loaded_.size() || !loaded_[r->sphere]))) {
    // The unit asked for geometry this memory does not hold: a wiring or assignment bug.
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  ++bursts_;
  bytes_read_ += p.get_data_length();
  p.set_response_status(tlm::TLM_OK_RESPONSE);
  if (!is_cache_ || !r->stream) {
    delay += latency_;
    return;
  }
  // A cache: time the visit line by line. Each miss is sent when it is due; with `sync` the
  // memory first waits until then, so that DRAM sees every unit's requests in time order.
  const std::uint64_t line_bytes = cache_.line_bytes();
  auto fetch = [&](std::uint64_t line, std::uint64_t t) {
    const sc_time due = at(t);
    if (r->sync && due > sc_time_stamp()) wait(due - sc_time_stamp());
    MemoryFillPacket f{static_cast<std::uint32_t>(unit_), line * line_bytes};
    fill_.set_command(tlm::TLM_READ_COMMAND);
    fill_.set_address(addr::dram);
    fill_.set_data_ptr(reinterpret_cast<unsigned char*>(&f));
    fill_.set_data_length(static_cast<unsigned>(line_bytes));
    fill_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
    sc_time d = due > sc_time_stamp() ? due - sc_time_stamp() : SC_ZERO_TIME;
    fill->b_transport(fill_, d);
    if (fill_.is_response_error()) SC_REPORT_FATAL(name(), "cache line fill from DRAM failed");
    const sc_time arrival = sc_time_stamp() + d;
    if (vcd_) {
      vcd_->change_by(vcd_misses_, due.value(), 1);
      vcd_->change_by(vcd_misses_, arrival.value(), -1);
    }
    return cycles(arrival);
  };
  // The unit's stalls, as they happen (never before simulation time: a miss sent late by a
  // full miss window can make the unit wait from a time the memory has already passed).
  auto state = [&](int code, std::uint64_t t) {
    if (vcd_ && r->state_var >= 0)
      vcd_->change(r->state_var, std::max(this->at(t), sc_time_stamp()).value(),
                   static_cast<std::uint64_t>(code));
  };
  const std::uint64_t stall_before = counts_.stall;
  const std::uint64_t end =
      time_visit(*r->costs, *r->stream, cycles(sc_time_stamp() + delay), cache_, window_, counts_, fetch, state);
  r->stall = counts_.stall - stall_before;
  delay = at(end) - sc_time_stamp();
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
  if (l->cache && !is_cache_) {  // it held its spheres whole until now: a cold cache
    const auto& c = arch_.memory.cache;
    cache_ = Cache(arch_.memory.sram_bytes, static_cast<std::uint32_t>(c.line_bytes), static_cast<std::uint32_t>(c.ways),
                   c.replacement, static_cast<std::uint64_t>(unit_) + 1);
    window_ = MissWindow(static_cast<std::uint32_t>(c.misses_outstanding));
  }
  is_cache_ = l->cache;
  if (is_cache_)
    for (const auto& [first, end] : l->rewritten)
      cache_.invalidate(first / cache_.line_bytes(), (end + cache_.line_bytes() - 1) / cache_.line_bytes());
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

}  // namespace oprt::hw
