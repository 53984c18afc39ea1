#include "hw/memory_timing.h"

namespace oprt::hw {

std::uint64_t stream_stall(std::uint32_t latency, std::uint32_t bpc, std::uint32_t bytes, std::uint32_t transform,
                           const std::uint8_t* stages, std::uint32_t n, const std::uint32_t* cost) {
  std::uint64_t t = transform, work = transform;
  for (std::uint32_t j = 0; j < n; ++j) {
    const std::uint64_t arrive = latency + (static_cast<std::uint64_t>(j + 1) * bytes + bpc - 1) / bpc;
    if (arrive > t) t = arrive;
    t += cost[stages[j]];
    work += cost[stages[j]];
  }
  if (n == 0) {  // a sphere hit whose first triangle test was not reached cannot happen
    return 0;
  }
  return t - work;
}

}  // namespace oprt::hw
