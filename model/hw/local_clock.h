// A process's notion of "now". Three ways to keep it:
//  - exact (`at`): every delay is waited for, so local time is simulation time.
//  - quantum (`lt`): the process runs ahead of simulation time by up to a quantum
//    (tlm_utils::tlm_quantumkeeper) and synchronises only when the quantum is used up or
//    before it blocks on an event.
//  - ahead: the process never waits for its own delays. Exact, not an approximation, for a
//    process whose intermediate times no other process can observe: an intersection unit
//    with an unbounded ray FIFO (nothing waits for room) and an ideal bus (its answers take
//    no bus time and contend with nothing). Its answers carry their times as annotated
//    delays, and the GPP acts on each answer only when simulation time reaches it
//    (gpp.cpp), so every figure is the one it would be with `exact` (a test compares them).
//    Local time is then the time its last ray finished, or simulation time if later.
#pragma once

#include "base/error.h"
#include "base/numbers.h"

#include <algorithm>

#include <systemc>
#include <tlm_utils/tlm_quantumkeeper.h>

namespace oprt::hw {

// Simulated time is SystemC's 64-bit count of picoseconds. A delay that would carry a
// process's time past its largest value, 2^64 - 1 ps (about 213 days), is refused where the
// time is formed, here, rather than wrapped: an InputError whose file is kSimulatedTime, which
// the testbench rewords with the settings that make the time so long.
constexpr const char* kSimulatedTime = "simulated time";

[[noreturn]] inline void time_overflow(const sc_core::sc_time& at, const sc_core::sc_time& delay) {
  throw InputError(kSimulatedTime, "at " + format_time_ps(at.value()),
                   "a delay of " + format_time_ps(delay.value()) +
                       " would pass 2^64 - 1 ps (about 213 days), the longest time SystemC can hold");
}
inline void check_fits(const sc_core::sc_time& at, const sc_core::sc_time& delay) {
  if (delay.value() > sc_core::sc_max_time().value() - at.value()) time_overflow(at, delay);
}

class LocalClock {
 public:
  enum class Mode { exact, quantum, ahead };
  explicit LocalClock(Mode mode) : mode_(mode) { qk_.reset(); }

  Mode mode() const { return mode_; }
  sc_core::sc_time now() const {
    switch (mode_) {
      case Mode::exact: return sc_core::sc_time_stamp();
      case Mode::quantum: return qk_.get_current_time();
      case Mode::ahead: return std::max(ahead_, sc_core::sc_time_stamp());
    }
    return sc_core::sc_time_stamp();
  }
  // Time ahead of the simulation kernel (annotated on outgoing transactions).
  sc_core::sc_time offset() const { return now() - sc_core::sc_time_stamp(); }

  void advance(const sc_core::sc_time& d) {
    if (d == sc_core::SC_ZERO_TIME) return;
    check_fits(now(), d);
    switch (mode_) {
      case Mode::exact: sc_core::wait(d); return;
      case Mode::quantum:
        qk_.inc(d);
        if (qk_.need_sync()) qk_.sync();
        return;
      case Mode::ahead: ahead_ = now() + d; return;
    }
  }
  void advance_to(const sc_core::sc_time& t) {
    const sc_core::sc_time n = now();
    if (t > n) advance(t - n);
  }
  // Before blocking on an event under `quantum`: bring simulation time up to local time.
  // (`ahead` keeps its local time across the wait: a ray that arrives meanwhile starts
  // when the unit is free, whichever is later.)
  void sync() {
    if (mode_ == Mode::quantum && qk_.get_local_time() != sc_core::SC_ZERO_TIME) qk_.sync();
  }
  // Let simulation time catch up with local time: what `exact` does after every delay, so
  // it changes no figure; a unit running ahead does it when its trace must be written
  // (vcd_writer.h).
  void catch_up() {
    if (mode_ == Mode::quantum) sync();
    else if (mode_ == Mode::ahead && ahead_ > sc_core::sc_time_stamp()) sc_core::wait(ahead_ - sc_core::sc_time_stamp());
  }
  // After blocking: local time restarts at simulation time.
  void resync() {
    if (mode_ == Mode::quantum) qk_.reset();
  }

 private:
  Mode mode_;
  tlm_utils::tlm_quantumkeeper qk_;
  sc_core::sc_time ahead_;
};

}  // namespace oprt::hw
