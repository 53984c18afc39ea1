// Stopping a run cleanly on SIGINT or SIGTERM. The handler only records the signal; the
// renderers look at it between rays (the GPP) or rows (the reference) and stop there, so a
// file being written is finished (and renamed into place) or never started. A second
// signal takes the default action at once.
#pragma once

#include <stdexcept>
#include <string>

namespace oprt {

void install_stop_handlers();
// 0, or the signal that asked the run to stop.
int stop_signal();
// For tests: forget a recorded signal.
void clear_stop_signal();

class Interrupted : public std::runtime_error {
 public:
  // `what_completed`: e.g. "frames 0:2 of 0:9 completed and written; frame 3 abandoned".
  explicit Interrupted(int signal, const std::string& what_completed = "");
  int signal() const { return signal_; }

 private:
  int signal_;
};

inline void throw_if_stopped() {
  if (const int s = stop_signal()) throw Interrupted(s);
}

std::string signal_name(int signal);  // "SIGINT"

// "frames 0:2 of 0:9 completed; frame 3 abandoned" (or "no frame completed; ...").
std::string frames_completed(int first, int last, int completed);

}  // namespace oprt
