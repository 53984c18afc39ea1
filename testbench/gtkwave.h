// A GTKWave save file for a trace: the GPP, the bus, then one group per intersection unit
// (its state, shown by name through a translate filter, and its FIFO occupancy).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

struct TraceSignal {
  std::string name;  // "scope.name"
  int width;
};

// Writes SAVE (e.g. trace.gtkw) and, beside it, the state-name filter.
// `end_ps` is the trace's last time: the view opens showing all of it.
void write_gtkwave_save(const std::string& vcd_path, const std::string& save_path,
                        const std::vector<TraceSignal>& signals, std::uint64_t end_ps);

}  // namespace oprt
