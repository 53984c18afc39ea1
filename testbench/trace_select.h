// What a run traces: --trace-frames, --trace-window, --trace-units and --trace-signals, for
// both the waveform (--vcd) and the timeline (--timeline); and which signal group and unit
// each traced signal belongs to (the filters and the GTKWave save file both ask).
#pragma once

#include "options.h"
#include "base/numbers.h"  // parse_time_ps, format_time_ps

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace oprt {

struct SignalKind {
  std::string group;  // "state", "fifo", "bus", "gpp"; "" if no group claims it
  int unit = -1;      // the intersection unit it belongs to, -1 for the GPP and the bus
};

// By the signal's scope ("testbench.engine.iu3") and name ("state"). A new kind of signal
// gets its group from one row of the table in trace_select.cpp.
SignalKind classify_signal(const std::string& scope, const std::string& name);
// Every group --trace-signals accepts, in the table's order.
std::vector<std::string> signal_groups();

struct TraceSelection {
  static constexpr std::uint64_t kNever = ~std::uint64_t{0};
  std::optional<FrameRange> frames;         // --trace-frames (inclusive)
  std::uint64_t from_ps = 0, to_ps = kNever;  // --trace-window
  std::vector<int> units;                   // --trace-units; empty: every unit
  std::vector<std::string> groups;          // --trace-signals; empty: every group

  // A signal, or a timeline track showing `group`, of the block `scope`.
  bool traces(const std::string& scope, const std::string& group) const;
  bool traces_signal(const std::string& scope, const std::string& name) const;
};

// Parsers of the options' values; each throws InputError naming the option, the value and
// the problem. `rendered` are the frames the run renders.
FrameRange parse_trace_frames(const std::string& text, const FrameRange& rendered);
// "T0:T1" with units ("10us:2ms"); either side may be empty (from the start / to the end).
void parse_trace_window(const std::string& text, std::uint64_t& from_ps, std::uint64_t& to_ps);
// "0-3,7": units and inclusive ranges, sorted and without repeats.
std::vector<int> parse_trace_units(const std::string& text);
// Checks units against the run's unit count.
void check_trace_units(const std::string& text, const std::vector<int>& units, std::size_t unit_count);
// "state,fifo,bus,gpp,memory,stage".
std::vector<std::string> parse_trace_signals(const std::string& text);

}  // namespace oprt
