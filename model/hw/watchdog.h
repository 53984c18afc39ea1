// The deadlock watchdog. A frame in the timed model ends when every ray has retired; if
// instead every process waits for something that never happens, the SystemC kernel runs out
// of events and sc_start() returns with the frame unfinished. The watchdog looks only then:
// it costs nothing while the model runs (no clock, no timer, no periodic event). It asks
// every module that waits what it is waiting for, and reports them all.
#pragma once

#include <stdexcept>
#include <string>

namespace oprt::hw {

// A module with a process that can block: says what it waits for now, and the state of
// the queue it waits on (one line, without its name).
class Waiter {
 public:
  virtual ~Waiter() = default;
  virtual std::string waiting_for() const = 0;
};

class Deadlock : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "  NAME: WHAT IT WAITS FOR" for every Waiter in the module hierarchy, in name order.
std::string waiters_report();

// Call after sc_start() returned. If the kernel has nothing left to do while `unfinished`
// describes work still outstanding (non-empty), throws Deadlock naming every blocked unit.
void check_deadlock(const std::string& unfinished);

}  // namespace oprt::hw
