// What a transfer costs, written once for the SystemC modules (hw/bus.cpp, hw/dram.cpp) and
// the plain-C++ timing (the analytic level, object_memory_model.cpp).
#pragma once

#include "arch/arch.h"

#include <cstdint>

namespace oprt::timing {

// The bus (hw/bus.h): a shared bus is held arbitration_cycles + ceil(bytes / bytes_per_cycle)
// cycles by a transfer.
inline std::uint64_t bus_occupancy(const Arch& a, std::uint64_t bytes) {
  const auto width = static_cast<std::uint64_t>(a.bus.bytes_per_cycle);
  return static_cast<std::uint64_t>(a.bus.arbitration_cycles) + (bytes + width - 1) / width;
}

// A DRAM channel (hw/dram.h) moves one cache line in ceil(line_bytes / bytes_per_cycle) cycles;
// the line arrives latency_cycles after that.
inline std::uint64_t dram_line_cycles(const Arch& a) {
  const auto width = static_cast<std::uint64_t>(a.memory.dram.bytes_per_cycle);
  return (static_cast<std::uint64_t>(a.memory.cache.line_bytes) + width - 1) / width;
}

}  // namespace oprt::timing
