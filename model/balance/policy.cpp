#include "balance/policy.h"

#include <stdexcept>

namespace oprt {

std::vector<double> sa_n_weights(const std::vector<SphereDef>& spheres) {
  std::vector<double> w;
  w.reserve(spheres.size());
  for (const SphereDef& s : spheres) w.push_back(s.sa_n());
  return w;
}

Assignment static_assignment(const std::string& policy, const std::vector<SphereDef>& spheres, std::size_t units) {
  if (policy == "paper") return assign_paper(spheres.size(), units);
  if (policy == "round_robin") return assign_round_robin(spheres.size(), units);
  if (policy == "sa_n") return assign_weighted(sa_n_weights(spheres), units);
  throw std::invalid_argument("static_assignment: policy " + policy + " is not static");
}

}  // namespace oprt
