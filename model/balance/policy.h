// The --balance policies that need only the scene's spheres (static over the animation).
#pragma once

#include "balance/assign.h"

#include <string>

namespace oprt {

// "paper", "round_robin" or "sa_n"; units = min(requested, spheres).
Assignment static_assignment(const std::string& policy, const std::vector<SphereDef>& spheres, std::size_t units);

// Per-sphere surface area x primitive count.
std::vector<double> sa_n_weights(const std::vector<SphereDef>& spheres);

}  // namespace oprt
