#include "balance/replicate.h"

#include <algorithm>
#include <stdexcept>

namespace oprt {

namespace {
// When unit u's last work would be done: its work in slice i arrives from slice i's start
// (issue * i / slices) on, and the unit works through it in order.
double finish(const double* load, std::size_t slices, double issue) {
  double f = 0, after = 0;
  for (std::size_t i = slices; i-- > 0;) {
    after += load[i];
    f = std::max(f, issue * static_cast<double>(i) / static_cast<double>(slices) + after);
  }
  return f;
}
}  // namespace

Assignment replicate(const Assignment& partition, const ReplicateInputs& in) {
  const std::size_t n = partition.units(), spheres = in.bytes.size();
  const std::size_t slices = in.slices ? in.slices : 1;
  const bool by_slice = in.slices != 0;
  if ((by_slice ? in.weight_slices.size() != spheres * slices : in.weight.size() != spheres) ||
      (!in.unit_extra.empty() && in.unit_extra.size() != n) || (!in.reach.empty() && in.reach.size() != spheres) ||
      (!in.ray_cycles.empty() && in.ray_cycles.size() != n))
    throw std::invalid_argument("replicate: sizes differ");
  auto weight = [&](std::uint32_t s, std::size_t i) { return by_slice ? in.weight_slices[s * slices + i] : in.weight[s]; };
  std::vector<double> total(spheres, 0);
  for (std::uint32_t s = 0; s < spheres; ++s)
    for (std::size_t i = 0; i < slices; ++i) total[s] += weight(s, i);
  std::vector<std::vector<char>> holds(n, std::vector<char>(spheres, 0));
  std::vector<std::uint32_t> copies(spheres, 0);
  std::vector<double> load(n * slices, 0), end(n, 0);
  std::vector<std::uint64_t> used(n, 0);
  std::uint64_t capacity = in.capacity;
  for (std::size_t u = 0; u < n; ++u) {
    if (!in.unit_extra.empty()) load[u * slices] = in.unit_extra[u];
    for (std::uint32_t s : partition.unit[u]) {
      if (s >= spheres) throw std::invalid_argument("replicate: sphere out of range");
      holds[u][s] = 1;
      ++copies[s];
      used[u] += in.bytes[s];
    }
  }
  if (!capacity) capacity = n ? *std::max_element(used.begin(), used.end()) : 0;
  for (std::size_t u = 0; u < n; ++u) {
    for (std::uint32_t s : partition.unit[u])
      for (std::size_t i = 0; i < slices; ++i) load[u * slices + i] += weight(s, i) / copies[s];
    end[u] = finish(&load[u * slices], slices, in.issue);
  }
  const std::size_t max_copies = in.max_copies ? std::min(in.max_copies, n) : n;

  std::uint64_t spent = 0;  // the copies' bytes so far
  Assignment out = partition;
  std::vector<std::uint32_t> order;
  std::vector<double> trial(slices);
  // A new copy's overhead on unit u, over the slices as the sphere's work.
  auto overhead = [&](std::size_t u, std::uint32_t s, double share) {
    if (in.reach.empty() || in.ray_cycles.empty() || total[s] <= 0) return 0.0;
    return in.reach[s] * share * in.ray_cycles[u] / total[s];
  };
  // Unit u's finish with `delta` per unit of sphere s's weight added in each slice (and a
  // new copy's overhead, with `extra`).
  auto finish_with = [&](std::size_t u, std::uint32_t s, double delta, double extra = 0) {
    for (std::size_t i = 0; i < slices; ++i) trial[i] = load[u * slices + i] + (delta + extra) * weight(s, i);
    return finish(trial.data(), slices, in.issue);
  };
  for (std::size_t step = 0; step < spheres * n; ++step) {
    const std::size_t top = static_cast<std::size_t>(std::max_element(end.begin(), end.end()) - end.begin());
    order.clear();
    for (std::uint32_t s : out.unit[top])
      if (copies[s] < max_copies && total[s] > 0) order.push_back(s);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      const double wa = total[a] / copies[a], wb = total[b] / copies[b];
      return wa != wb ? wa > wb : a < b;
    });
    bool applied = false;
    for (std::uint32_t s : order) {
      if (in.budget && spent + in.bytes[s] > in.budget) continue;
      const double k = copies[s], share = 1 / (k + 1), change = 1 / (k + 1) - 1 / k;
      std::size_t v = n;
      double v_end = 0;
      for (std::size_t u = 0; u < n; ++u) {
        if (holds[u][s] || used[u] + in.bytes[s] > capacity) continue;
        const double e = finish_with(u, s, share, overhead(u, s, share));
        if (v == n || e < v_end) {
          v = u;
          v_end = e;
        }
      }
      if (v == n) continue;
      double worst = v_end;
      for (std::size_t u = 0; u < n; ++u)
        if (u != v) worst = std::max(worst, holds[u][s] ? finish_with(u, s, change) : end[u]);
      if (!(worst < end[top] * (1 - 1e-9))) continue;
      for (std::size_t u = 0; u < n; ++u) {
        if (!holds[u][s] && u != v) continue;
        const double delta = u == v ? share + overhead(u, s, share) : change;
        for (std::size_t i = 0; i < slices; ++i) load[u * slices + i] += delta * weight(s, i);
        end[u] = finish(&load[u * slices], slices, in.issue);
      }
      holds[v][s] = 1;
      ++copies[s];
      used[v] += in.bytes[s];
      spent += in.bytes[s];
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
