#include "ref/memory_timing.h"

namespace oprt {

std::uint64_t stream_stall(const StreamCosts& c, const std::uint8_t* items, std::uint32_t n) {
  constexpr std::uint8_t kNode = 0xFF;  // ref/bvh_traverse.h kLogNode
  std::uint64_t t = c.lead, work = c.lead;
  std::uint64_t request = 0, j = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const bool node = items[i] == kNode;
    if (i > 0 && (node || items[i - 1] == kNode)) {  // a new, dependent burst
      request = t;
      j = 0;
    }
    const std::uint64_t bytes = node ? c.node_bytes : c.triangle_bytes;
    const std::uint64_t arrive = request + c.latency + ((j + 1) * bytes + c.bytes_per_cycle - 1) / c.bytes_per_cycle;
    if (arrive > t) t = arrive;
    const std::uint64_t cost = node ? c.box : c.triangle[items[i]];
    t += cost;
    work += cost;
    ++j;
  }
  return t - work;
}

}  // namespace oprt
