#include "hw/object_memory.h"

#include "hw/extensions.h"

#include <algorithm>

namespace oprt::hw {

using timing::fills_leave_memory;

using namespace sc_core;

ObjectMemory::ObjectMemory(const sc_module_name& name, int unit, const Arch& arch, std::size_t spheres,
                           VcdWriter* vcd)
    : sc_module(name),
      read("read"),
      load("load"),
      fill("fill"),
      unit_(unit),
      cycle_(arch.cycle_ns(), SC_NS),
      model_(arch, static_cast<std::uint32_t>(unit)),
      fill_base_(arch.memory.dram.path == DramPath::channel ? 0 : addr::dram_base),
      loaded_(spheres, 0),
      vcd_(vcd) {
  read.register_b_transport(this, &ObjectMemory::read_transport);
  load.register_b_transport(this, &ObjectMemory::load_transport);
  if (vcd_ && arch.memory.sram_bytes && (vcd_misses_ = vcd_->add_counter(this->name(), "misses", 16)) == VcdWriter::kNotTraced)
    vcd_ = nullptr;
  if (!vcd_) vcd_misses_ = -1;
  if (fills_leave_memory(arch)) model_.set_fill(this);
}

void ObjectMemory::read_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  const auto* r = extension_of<VisitReadExtension>(p);
  if (!r) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  const bool whole_ray = r->sphere == kNone;  // a ray's reads over all its entered spheres
  if (p.get_command() != tlm::TLM_READ_COMMAND || (!whole_ray && (r->sphere >= loaded_.size() || !loaded_[r->sphere]))) {
    // The unit asked for geometry this memory does not hold: a wiring or assignment bug.
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  bytes_read_ += p.get_data_length();
  p.set_response_status(tlm::TLM_OK_RESPONSE);
  if (!r->stream) return;
  // Time the visit's bursts; with `sync` each miss is sent when it is due (fetch), so that
  // a DRAM channel shared with other units sees every unit's requests in time order.
  sync_ = r->sync;
  model_.forget_before(r->horizon);
  const Cycle end = model_.visit(*r->stream, cycles(sc_time_stamp() + delay), *r->unit);
  delay = std::max(at(end), sc_time_stamp()) - sc_time_stamp();
}

Cycle ObjectMemory::fetch(std::uint64_t address, Cycle t) {
  const sc_time due = at(t);
  if (sync_ && due > sc_time_stamp()) wait(due - sc_time_stamp());
  FillExtension& f = prepare<FillExtension>(fill_, tlm::TLM_READ_COMMAND, fill_base_ + address, nullptr, 0u);
  f.unit = static_cast<std::uint32_t>(unit_);
  const unsigned line_bytes = static_cast<unsigned>(model_.line_bytes());
  fill_.set_data_ptr(line_.data(line_bytes));
  fill_.set_data_length(line_bytes);
  fill_.set_streaming_width(line_bytes);
  sc_time d = due > sc_time_stamp() ? due - sc_time_stamp() : SC_ZERO_TIME;
  fill->b_transport(fill_, d);
  if (fill_.is_response_error()) SC_REPORT_FATAL(name(), "cache line fill from DRAM failed");
  const sc_time arrival = sc_time_stamp() + d;
  if (vcd_) {
    vcd_->change_by(vcd_misses_, due.value(), 1);
    vcd_->change_by(vcd_misses_, arrival.value(), -1);
  }
  return cycles(arrival);
}

void ObjectMemory::load_transport(tlm::tlm_generic_payload& p, sc_time&) {
  const auto* e = extension_of<LoadExtension>(p);
  if (p.get_command() != tlm::TLM_WRITE_COMMAND) {
    p.set_response_status(tlm::TLM_COMMAND_ERROR_RESPONSE);
    return;
  }
  if (!e || !e->load || !e->load->spheres) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  std::fill(loaded_.begin(), loaded_.end(), 0);
  loaded_count_ = 0;
  for (std::uint32_t s : *e->load->spheres) {
    if (s >= loaded_.size()) {
      p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
      return;
    }
    loaded_[s] = 1;
    ++loaded_count_;
  }
  model_.load(*e->load);
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

}  // namespace oprt::hw
