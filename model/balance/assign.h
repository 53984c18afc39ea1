// Which intersection unit holds which bounding spheres. An assignment is a partition: every
// sphere on exactly one unit; within a unit the spheres are tested in scene order.
#pragma once

#include "balance/spheres.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

struct Assignment {
  std::vector<std::vector<std::uint32_t>> unit;  // per unit: its spheres, ascending

  std::size_t units() const { return unit.size(); }
  // unit_of[s]: the unit holding sphere s.
  std::vector<std::uint32_t> unit_of(std::size_t spheres) const;
  bool is_partition(std::size_t spheres) const;
};

// Units used: min(requested, spheres) -- a unit with no sphere would only answer "miss".
std::size_t units_for(std::size_t spheres, std::size_t requested);

// The paper's evaluation: sphere i on unit i (spheres == units), or contiguous runs of
// spheres in scene order when there are more spheres than units.
Assignment assign_paper(std::size_t spheres, std::size_t units);
// Sphere i on unit i mod units.
Assignment assign_round_robin(std::size_t spheres, std::size_t units);
// Longest-processing-time greedy on per-sphere weights: spheres by decreasing weight
// (ties: lower index first), each to the unit with the least total so far (ties: lower
// unit). Makespan within 4/3 - 1/(3 units) of the optimum (Graham 1969).
Assignment assign_weighted(const std::vector<double>& weight, std::size_t units);

// The sum of weights on each unit.
std::vector<double> unit_loads(const Assignment& a, const std::vector<double>& weight);

}  // namespace oprt
