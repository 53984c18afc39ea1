#include "hw/dram.h"

#include "hw/extensions.h"
#include "hw/local_clock.h"
#include "timing/transfers.h"

namespace oprt::hw {

using timing::dram_line_cycles;

using namespace sc_core;

Dram::Dram(const sc_module_name& name, const Arch& arch, std::size_t units, std::uint64_t base)
    : sc_module(name),
      in("in"),
      cycle_(arch.cycle_ns(), SC_NS),
      latency_(cycle_ * static_cast<double>(arch.memory.dram.latency_cycles)),
      transfer_(cycle_ * static_cast<double>(dram_line_cycles(arch))),
      units_per_channel_(static_cast<std::uint32_t>(arch.memory.dram.units_per_channel)),
      base_(base),
      channels_((units + units_per_channel_ - 1) / units_per_channel_ + 1) {
  in.register_b_transport(this, &Dram::b_transport);
}

void Dram::b_transport(int, tlm::tlm_generic_payload& p, sc_time& delay) {
  const auto* f = extension_of<FillExtension>(p);
  if (!f) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  const std::size_t channel = f->unit / units_per_channel_;
  if (p.get_command() != tlm::TLM_READ_COMMAND || channel >= channels_.size() || p.get_address() < base_ ||
      p.get_address() - base_ >= addr::dram_size) {
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  Calendar<sc_time>& c = channels_[channel];
  c.forget_before(sc_time_stamp());  // every requester's time is at or after simulation time
  sc_time start;
  const sc_time request = sc_time_stamp() + delay;
  check_fits(request, transfer_);
  const sc_time end = c.reserve(request, transfer_, &start);
  if (end < request) time_overflow(request, transfer_);  // the calendar's end wrapped: refused
  check_fits(end, latency_);
  delay = end + latency_ - sc_time_stamp();
  bytes_ += p.get_data_length();
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

}  // namespace oprt::hw
