#include "hw/bus.h"

#include "hw/local_clock.h"
#include "timing/transfers.h"

#include <algorithm>

namespace oprt::hw {

using timing::bus_occupancy;

using namespace sc_core;

Bus::Bus(const sc_module_name& name, const Arch& arch, bool decoupled, VcdWriter* vcd, TimelineWriter* timeline)
    : sc_module(name),
      in("in"),
      out("out"),
      shared_(arch.bus.model == BusModel::shared),
      decoupled_(decoupled),
      arch_(arch),
      cycle_(arch.cycle_ns(), SC_NS),
      arbiter_(decoupled && arch.bus.lt_arbitration == LtArbitration::busy_until),
      vcd_(vcd),
      timeline_(timeline) {
  in.register_b_transport(this, &Bus::b_transport);
  if (vcd_) vcd_busy_ = vcd_->add(this->name(), "busy", 1);
  if (timeline_ && (track_ = timeline_->track(this->name(), "bus", "bus")) == TimelineWriter::kNotTraced)
    timeline_ = nullptr;
}

void Bus::map(std::uint64_t base, std::uint64_t size, std::vector<int> targets, const char* what, bool masked) {
  auto at = std::upper_bound(regions_.begin(), regions_.end(), base,
                             [](std::uint64_t b, const Region& r) { return b < r.base; });
  if ((at != regions_.end() && base + size > at->base) ||
      (at != regions_.begin() && std::prev(at)->base + std::prev(at)->size > base))
    SC_REPORT_FATAL(name(), "overlapping address regions");
  regions_.insert(at, {base, size, std::move(targets), what, masked});
  last_ = ~std::size_t{0};
}

void Bus::b_transport(int, tlm::tlm_generic_payload& p, sc_time& delay) {
  const std::uint64_t a = p.get_address();
  const Region* r = last_ < regions_.size() ? &regions_[last_] : nullptr;  // most transfers repeat the last region
  if (!r || a < r->base || a - r->base >= r->size) {
    auto it = std::upper_bound(regions_.begin(), regions_.end(), a,
                               [](std::uint64_t x, const Region& g) { return x < g.base; });
    r = it == regions_.begin() ? nullptr : &*std::prev(it);
    if (!r || a - r->base >= r->size) {
      p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
      return;
    }
    last_ = static_cast<std::size_t>(r - regions_.data());
  }
  ++transfers_;
  bytes_ += p.get_data_length();
  if (shared_) {
    const std::uint64_t cycles = bus_occupancy(arch_, p.get_data_length());
    busy_cycles_ += cycles;
    arbiter_.forget_before(sc_time_stamp());
    sc_time start;
    const sc_time request = sc_time_stamp() + delay, length = cycle_ * static_cast<double>(cycles);
    check_fits(request, length);
    const sc_time end = arbiter_.reserve(request, length, &start);
    if (end < request) time_overflow(request, length);  // the calendar's end wrapped: refused
    if (vcd_) {
      vcd_->change(vcd_busy_, start.value(), 1);
      vcd_->change(vcd_busy_, end.value(), 0);
    }
    if (timeline_) timeline_->slice(track_, r->what, start.value(), end.value(), {{"bytes", p.get_data_length()}});
    if (decoupled_) {
      delay = end - sc_time_stamp();
    } else {
      wait(end - sc_time_stamp());  // until the transfer completes
      delay = SC_ZERO_TIME;
    }
  }
  p.set_address(a - r->base);
  p.set_response_status(tlm::TLM_OK_RESPONSE);
  const std::size_t mask_bytes = r->masked ? (r->targets.size() + 7) / 8 : 0;
  if (mask_bytes > p.get_data_length()) p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
  const unsigned char* mask = p.get_data_ptr() + p.get_data_length() - mask_bytes;
  for (std::size_t i = 0; i < r->targets.size() && p.get_response_status() == tlm::TLM_OK_RESPONSE; ++i) {
    if (r->masked && !(mask[i / 8] & (1u << (i % 8)))) continue;
    sc_time d = delay;
    out[r->targets[i]]->b_transport(p, d);
  }
  p.set_address(a);
}

}  // namespace oprt::hw
