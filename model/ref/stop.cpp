#include "ref/stop.h"

#include <csignal>
#include <cstring>

namespace oprt {

namespace {
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_stop_signal(int s) {
  if (g_signal) {  // the second: stop now
    std::signal(s, SIG_DFL);
    std::raise(s);
    return;
  }
  g_signal = s;
}
}  // namespace

void install_stop_handlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sa.sa_flags = SA_RESTART;  // file writes in progress carry on
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int stop_signal() { return g_signal; }
void clear_stop_signal() { g_signal = 0; }

std::string signal_name(int s) {
  if (s == SIGINT) return "SIGINT";
  if (s == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(s);
}

Interrupted::Interrupted(int signal, const std::string& what_completed)
    : std::runtime_error("interrupted by " + signal_name(signal) + (what_completed.empty() ? "" : ": " + what_completed)),
      signal_(signal) {}

std::string frames_completed(int first, int last, int completed) {
  const std::string asked = std::to_string(first) + ":" + std::to_string(last);
  std::string s = completed == 0 ? "no frame of " + asked + " completed"
                  : completed == 1 ? "frame " + std::to_string(first) + " of " + asked + " completed"
                                   : "frames " + std::to_string(first) + ":" + std::to_string(first + completed - 1) +
                                         " of " + asked + " completed";
  if (first + completed <= last) s += "; frame " + std::to_string(first + completed) + " abandoned, nothing of it written";
  return s;
}

}  // namespace oprt
