#include "hw/ray_fifo.h"

#include "hw/extensions.h"

namespace oprt::hw {

using namespace sc_core;

RayFifo::RayFifo(const sc_module_name& name, int depth, VcdWriter* vcd)
    : sc_module(name), in("in"), depth_(depth), vcd_(vcd) {
  in.register_b_transport(this, &RayFifo::b_transport);
  if (vcd_ && (vcd_var_ = vcd_->add_counter(this->name(), "occupancy", 32)) == VcdWriter::kNotTraced) vcd_ = nullptr;
}


sc_time RayFifo::space_time() const {
  if (depth_ == 0 || pushes_ < static_cast<std::uint64_t>(depth_)) return SC_ZERO_TIME;
  return pop_time_[pushes_ - depth_ - pop_time_first_];  // has_space(): that pop has happened
}

void RayFifo::b_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  if (p.get_command() != tlm::TLM_WRITE_COMMAND) {
    p.set_response_status(tlm::TLM_COMMAND_ERROR_RESPONSE);
    return;
  }
  // Only reachable when a writer ignores the full flag: the write then waits for room,
  // holding whatever it holds (the bus). See the deadlock test.
  ++writes_waiting_;
  while (!has_space()) wait(freed_);
  --writes_waiting_;
  if (p.get_data_length() < 4) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  const std::uint32_t id = WireRay<float>::id(p.get_data_ptr());  // the ray's first 4 bytes, in either precision
  const sc_time at = sc_time_stamp() + delay;
  queue_.push_back({id, at});
  ++pushes_;
  unsettled_.emplace_back(at, pushes_);
  if (unsettled_.size() == 1)  // no push before it is left to count: pops at or before `at` no longer matter
    while (!late_pops_.empty() && late_pops_.front() <= at) late_pops_.pop_front();
  trace_occupancy(at, +1);
  pushed_.notify();
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

// Count the pushes before `before` (every pop at or before their time has happened), or all
// of them (null).
void RayFifo::settle(const sc_time* before) {
  while (!unsettled_.empty() && (!before || unsettled_.front().first < *before)) {
    const auto& [a, pushed] = unsettled_.front();
    while (!late_pops_.empty() && late_pops_.front() <= a) late_pops_.pop_front();
    const std::uint64_t popped = pops_ - late_pops_.size();  // the pops at or before a
    peak_ = std::max<std::size_t>(peak_, static_cast<std::size_t>(pushed - popped));
    unsettled_.pop_front();
  }
}

std::size_t RayFifo::peak_occupancy() {
  settle(nullptr);  // between frames every pop is done
  return peak_;
}

std::string RayFifo::fill_state() const {
  std::string s = "holds " + std::to_string(queue_.size()) + " rays";
  if (depth_ == 0) s += " (unbounded)";
  else s += " of " + std::to_string(depth_) + (has_space() ? "" : " (full)");
  if (!queue_.empty()) s += ", next ray " + std::to_string(queue_.front().ray);
  if (writes_waiting_) s += "; a write waits for room";
  return s;
}

bool RayFifo::pop(RayEntry& e, const sc_time& at) {
  if (queue_.empty()) return false;
  e = queue_.front();
  queue_.pop_front();
  const sc_time t = std::max(at, e.avail);
  if (depth_ > 0) {
    // Pop i frees the slot of push i + depth: only pops from pushes - depth on are asked for.
    pop_time_.push_back(t);
    const std::uint64_t oldest = pushes_ > static_cast<std::uint64_t>(depth_) ? pushes_ - depth_ : 0;
    for (; pop_time_first_ < oldest && !pop_time_.empty(); ++pop_time_first_) pop_time_.pop_front();
  }
  settle(&t);
  ++pops_;
  late_pops_.push_back(t);
  trace_occupancy(t, -1);
  if (depth_ > 0) freed_.notify();  // only a bounded FIFO is ever waited on for room
  return true;
}

}  // namespace oprt::hw
