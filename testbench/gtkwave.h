// A GTKWave save file for a trace: the GPP, the bus, then one group per intersection unit
// (its state, shown by name through a translate filter, and its FIFO occupancy), each
// signal placed by its group and unit (trace_select.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

struct TraceSignal {
  std::string name;  // "scope.name"
  int width;
};

// Writes SAVE (e.g. trace.gtkw) for the trace (VCD or FST) and, beside it, the state-name
// filter. The trace spans [start_ps, end_ps]: the view opens showing all of it. It lists
// only `signals` (what was traced).
void write_gtkwave_save(const std::string& trace_path, const std::string& save_path,
                        const std::vector<TraceSignal>& signals, std::uint64_t start_ps, std::uint64_t end_ps);

}  // namespace oprt
