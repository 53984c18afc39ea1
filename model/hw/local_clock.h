// A process's notion of "now" at either timing level. At `at` every delay is waited for, so
// local time is simulation time. At `lt` the process runs ahead of simulation time by up to
// a quantum (tlm_utils::tlm_quantumkeeper) and synchronises only when the quantum is used
// up or before it blocks on an event.
#pragma once

#include <systemc>
#include <tlm_utils/tlm_quantumkeeper.h>

namespace oprt::hw {

class LocalClock {
 public:
  explicit LocalClock(bool decoupled) : decoupled_(decoupled) { qk_.reset(); }

  bool decoupled() const { return decoupled_; }
  sc_core::sc_time now() const { return decoupled_ ? qk_.get_current_time() : sc_core::sc_time_stamp(); }
  // Time ahead of the simulation kernel (annotated on outgoing transactions).
  sc_core::sc_time offset() const { return decoupled_ ? qk_.get_local_time() : sc_core::SC_ZERO_TIME; }

  void advance(const sc_core::sc_time& d) {
    if (d == sc_core::SC_ZERO_TIME) return;
    if (!decoupled_) {
      sc_core::wait(d);
      return;
    }
    qk_.inc(d);
    if (qk_.need_sync()) qk_.sync();
  }
  void advance_to(const sc_core::sc_time& t) {
    const sc_core::sc_time n = now();
    if (t > n) advance(t - n);
  }
  // Before blocking on an event: bring simulation time up to local time.
  void sync() {
    if (decoupled_ && qk_.get_local_time() != sc_core::SC_ZERO_TIME) qk_.sync();
  }
  // After blocking: local time restarts at simulation time.
  void resync() {
    if (decoupled_) qk_.reset();
  }

 private:
  bool decoupled_;
  tlm_utils::tlm_quantumkeeper qk_;
};

}  // namespace oprt::hw
