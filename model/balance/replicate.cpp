#include "balance/replicate.h"

#include <algorithm>
#include <stdexcept>

namespace oprt {

Assignment replicate(const Assignment& partition, const ReplicateInputs& in) {
  const std::size_t n = partition.units(), spheres = in.weight.size();
  if (in.bytes.size() != spheres || (!in.unit_extra.empty() && in.unit_extra.size() != n))
    throw std::invalid_argument("replicate: sizes differ");
  std::vector<std::vector<char>> holds(n, std::vector<char>(spheres, 0));
  std::vector<std::uint32_t> copies(spheres, 0);
  std::vector<double> load(n, 0);
  std::vector<std::uint64_t> used(n, 0);
  std::uint64_t capacity = in.capacity;
  for (std::size_t u = 0; u < n; ++u) {
    if (!in.unit_extra.empty()) load[u] = in.unit_extra[u];
    for (std::uint32_t s : partition.unit[u]) {
      if (s >= spheres) throw std::invalid_argument("replicate: sphere out of range");
      holds[u][s] = 1;
      ++copies[s];
      used[u] += in.bytes[s];
    }
  }
  if (!capacity) capacity = n ? *std::max_element(used.begin(), used.end()) : 0;
  for (std::size_t u = 0; u < n; ++u)
    for (std::uint32_t s : partition.unit[u]) load[u] += in.weight[s] / copies[s];
  const std::size_t max_copies = in.max_copies ? std::min(in.max_copies, n) : n;

  Assignment out = partition;
  std::vector<std::uint32_t> order;
  for (std::size_t step = 0; step < spheres * n; ++step) {
    const std::size_t top = static_cast<std::size_t>(std::max_element(load.begin(), load.end()) - load.begin());
    order.clear();
    for (std::uint32_t s : out.unit[top])
      if (copies[s] < max_copies && in.weight[s] > 0) order.push_back(s);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      const double wa = in.weight[a] / copies[a], wb = in.weight[b] / copies[b];
      return wa != wb ? wa > wb : a < b;
    });
    bool applied = false;
    for (std::uint32_t s : order) {
      std::size_t v = n;
      for (std::size_t u = 0; u < n; ++u)
        if (!holds[u][s] && used[u] + in.bytes[s] <= capacity && (v == n || load[u] < load[v])) v = u;
      if (v == n) continue;
      const double before = in.weight[s] / copies[s], after = in.weight[s] / (copies[s] + 1);
      double worst = load[v] + after;
      for (std::size_t u = 0; u < n; ++u)
        if (u != v) worst = std::max(worst, holds[u][s] ? load[u] - before + after : load[u]);
      if (!(worst < load[top] * (1 - 1e-9))) continue;
      for (std::size_t u = 0; u < n; ++u)
        if (holds[u][s]) load[u] += after - before;
      load[v] += after;
      holds[v][s] = 1;
      ++copies[s];
      used[v] += in.bytes[s];
      out.unit[v].insert(std::lower_bound(out.unit[v].begin(), out.unit[v].end(), s), s);
      applied = true;
      break;
    }
    if (!applied) break;
  }
  return out;
}

std::vector<Replica> replicas(const Assignment& a, std::size_t spheres) {
  std::vector<std::vector<std::uint32_t>> holders(spheres);
  for (std::uint32_t u = 0; u < a.units(); ++u)
    for (std::uint32_t s : a.unit[u])
      if (s < spheres) holders[s].push_back(u);
  std::vector<Replica> out;
  for (std::uint32_t s = 0; s < spheres; ++s)
    if (holders[s].size() > 1) out.push_back({s, holders[s]});
  return out;
}

std::uint64_t replica_bytes(const Assignment& a, const std::vector<std::uint64_t>& bytes) {
  std::uint64_t total = 0;
  for (const Replica& r : replicas(a, bytes.size())) total += (r.units.size() - 1) * bytes[r.sphere];
  return total;
}

}  // namespace oprt
