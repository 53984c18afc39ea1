// Object memory timing under the latency model (plain C++, shared by the SystemC unit and
// the analytic level).
#pragma once

#include <cstdint>

namespace oprt::hw {

// Stall cycles of one burst under the latency model: the transform (transform_cycles)
// starts with the request; triangle j (of n, bytes each) arrives at
// latency + ceil((j + 1) bytes / bytes_per_cycle); test j takes cost[j] cycles and starts
// when test j - 1 has ended and its data has arrived. Returns the cycles the unit waited.
std::uint64_t stream_stall(std::uint32_t latency, std::uint32_t bytes_per_cycle, std::uint32_t bytes,
                           std::uint32_t transform_cycles, const std::uint8_t* stages, std::uint32_t n,
                           const std::uint32_t* stage_cost);

}  // namespace oprt::hw
