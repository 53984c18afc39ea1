#include "hw/watchdog.h"

#include <functional>
#include <map>

#include <systemc>

namespace oprt::hw {

std::string waiters_report() {
  std::map<std::string, std::string> lines;  // by name: fifo10 after fifo1, but stable
  std::function<void(const std::vector<sc_core::sc_object*>&)> walk = [&](const auto& objects) {
    for (sc_core::sc_object* o : objects) {
      if (const auto* w = dynamic_cast<const Waiter*>(o)) lines[o->name()] = w->waiting_for();
      walk(o->get_child_objects());
    }
  };
  walk(sc_core::sc_get_top_level_objects());
  std::string out;
  for (const auto& [name, what] : lines) out += "  " + name + ": " + what + "\n";
  return out;
}

void check_deadlock(const std::string& unfinished) {
  if (unfinished.empty() || sc_core::sc_pending_activity()) return;
  throw Deadlock("deadlock at " + sc_core::sc_time_stamp().to_string() +
                 ": no process can run any more, and " + unfinished + ". Blocked:\n" + waiters_report());
}

}  // namespace oprt::hw
