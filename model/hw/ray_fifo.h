// RayFifo: the queue of rays in front of one intersection unit. The bus writes rays into it
// (a broadcast write enters every unit's FIFO); its unit pops them in order. Depth 0 means
// unbounded. It reports its full/space state to the GPP (the GPP does not start a ray write
// while any FIFO is full, so a full FIFO never holds the bus).
#pragma once

#include "trace/vcd_writer.h"
#include "hw/watchdog.h"

#include <cstdint>
#include <deque>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_target_socket.h>

namespace oprt::hw {

struct RayEntry {
  std::uint32_t ray = 0;
  sc_core::sc_time avail;  // when the write completed: the unit cannot start it earlier
};

class RayFifoIf : public virtual sc_core::sc_interface {
 public:
  virtual bool pop(RayEntry& e, const sc_core::sc_time& at) = 0;  // false if empty
  virtual const sc_core::sc_event& pushed_event() const = 0;
  virtual bool has_space() const = 0;
  // When the slot the next write will use was freed (under temporal decoupling the pop
  // that freed it may lie ahead of simulation time).
  virtual sc_core::sc_time space_time() const = 0;
  virtual const sc_core::sc_event& freed_event() const = 0;
  virtual std::size_t occupancy() const = 0;
  virtual std::string fill_state() const = 0;  // "holds 2 rays of 2 (full), ...": for the watchdog
};

class RayFifo : public sc_core::sc_module, public RayFifoIf, public Waiter {
 public:
  tlm_utils::simple_target_socket<RayFifo> in;

  RayFifo(const sc_core::sc_module_name& name, int depth, VcdWriter* vcd);

  bool pop(RayEntry& e, const sc_core::sc_time& at) override;
  const sc_core::sc_event& pushed_event() const override { return pushed_; }
  bool has_space() const override { return depth_ == 0 || pushes_ - pops_ < static_cast<std::uint64_t>(depth_); }
  sc_core::sc_time space_time() const override;
  const sc_core::sc_event& freed_event() const override { return freed_; }
  std::size_t occupancy() const override { return queue_.size(); }
  // Pushes and pops since reset_counts(), and the most rays it held at once over the run.
  // The peak is in time order, not simulation order: a unit running ahead pops a ray early
  // in simulation order at a time that lies ahead, so the queue's length when a ray is
  // pushed is not the occupancy at the push's time. Push times and pop times each only
  // grow, so a push at time a is counted once a pop later than a (or the end of a frame)
  // shows that every pop at or before a has happened: occupancy after the push = pushes up
  // to it - pops at or before a (a slot freed at a can be filled at a). Pops done early in
  // simulation order at times after a are not among them.
  std::uint64_t pushes() const { return pushes_ - pushes_at_reset_; }
  std::uint64_t pops() const { return pops_ - pops_at_reset_; }
  std::size_t peak_occupancy();
  void reset_counts() { pushes_at_reset_ = pushes_, pops_at_reset_ = pops_; }
  int depth() const { return depth_; }
  std::string fill_state() const override;
  std::string waiting_for() const override { return fill_state(); }

 private:
  void b_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  // not trace(): sc_object::trace is virtual
  // A push is reported at its time, a pop at its unit's (local) time, which may lie ahead of
  // simulation time: the trace is the running sum of both in time order (VcdWriter counter).
  void trace_occupancy(const sc_core::sc_time& at, int delta) {
    if (vcd_) vcd_->change_by(vcd_var_, at.value(), delta);
  }

  int depth_;
  std::deque<RayEntry> queue_;
  std::uint64_t pushes_ = 0, pops_ = 0;
  // Times of the pops that may still free a slot for a later push (at most `depth`, and no
  // more than the rays actually queued: a deep FIFO reserves nothing), the first being pop
  // number pop_time_first_.
  std::deque<sc_core::sc_time> pop_time_;
  std::uint64_t pop_time_first_ = 0;
  std::uint64_t pushes_at_reset_ = 0, pops_at_reset_ = 0;
  std::deque<std::pair<sc_core::sc_time, std::uint64_t>> unsettled_;  // pushes (time, pushes up to it) not yet counted
  std::deque<sc_core::sc_time> late_pops_;  // times of pops done, later than the pushes counted so far
  std::size_t peak_ = 0;
  void settle(const sc_core::sc_time* before);
  int writes_waiting_ = 0;
  sc_core::sc_event pushed_, freed_;
  VcdWriter* vcd_;
  int vcd_var_ = -1;
};

}  // namespace oprt::hw
