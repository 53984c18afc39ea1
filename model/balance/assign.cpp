#include "balance/assign.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace oprt {

std::vector<std::uint32_t> Assignment::unit_of(std::size_t spheres) const {
  std::vector<std::uint32_t> u(spheres, 0xFFFFFFFFu);
  for (std::size_t i = 0; i < unit.size(); ++i)
    for (std::uint32_t s : unit[i]) u.at(s) = static_cast<std::uint32_t>(i);
  return u;
}

bool Assignment::is_partition(std::size_t spheres) const {
  std::vector<int> seen(spheres, 0);
  for (const auto& u : unit)
    for (std::uint32_t s : u) {
      if (s >= spheres) return false;
      ++seen[s];
    }
  return std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; });
}

std::size_t units_for(std::size_t spheres, std::size_t requested) { return std::min(spheres, requested); }

Assignment assign_paper(std::size_t spheres, std::size_t units) {
  if (units == 0) throw std::invalid_argument("assign_paper: no units");
  Assignment a;
  a.unit.resize(units);
  for (std::size_t s = 0; s < spheres; ++s) a.unit[s * units / spheres].push_back(static_cast<std::uint32_t>(s));
  return a;
}

Assignment assign_round_robin(std::size_t spheres, std::size_t units) {
  if (units == 0) throw std::invalid_argument("assign_round_robin: no units");
  Assignment a;
  a.unit.resize(units);
  for (std::size_t s = 0; s < spheres; ++s) a.unit[s % units].push_back(static_cast<std::uint32_t>(s));
  return a;
}

Assignment assign_weighted(const std::vector<double>& w, std::size_t units) {
  if (units == 0) throw std::invalid_argument("assign_weighted: no units");
  std::vector<std::uint32_t> order(w.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return w[a] > w[b]; });
  Assignment a;
  a.unit.resize(units);
  std::vector<double> load(units, 0);
  for (std::uint32_t s : order) {
    const std::size_t u = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    a.unit[u].push_back(s);
    load[u] += w[s];
  }
  for (auto& u : a.unit) std::sort(u.begin(), u.end());
  return a;
}

std::vector<double> unit_loads(const Assignment& a, const std::vector<double>& w) {
  std::vector<double> load(a.units(), 0);
  for (std::size_t i = 0; i < a.units(); ++i)
    for (std::uint32_t s : a.unit[i]) load[i] += w[s];
  return load;
}

}  // namespace oprt
