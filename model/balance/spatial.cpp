#include "balance/spatial.h"

#include "balance/partition_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace oprt {

namespace {

Box<double> box_of(const std::vector<std::uint32_t>& ids, std::size_t from, std::size_t to,
                   const std::vector<Box<double>>& box) {
  Box<double> b;
  for (std::size_t i = from; i < to; ++i) b.extend(box[ids[i]]);
  return b;
}

void sort_on(std::vector<std::uint32_t>& ids, int axis, const std::vector<Vec3d>& centre) {
  std::sort(ids.begin(), ids.end(), [&](std::uint32_t a, std::uint32_t b) {
    return centre[a][axis] < centre[b][axis] || (centre[a][axis] == centre[b][axis] && a < b);
  });
}

// Recursion depth is log2(groups): no stack concern.
void split(std::vector<std::uint32_t> ids, std::size_t k, const std::vector<Box<double>>& box,
           const std::vector<double>& w, const std::vector<Vec3d>& centre,
           std::vector<std::vector<std::uint32_t>>& out) {
  const std::size_t n = ids.size();
  if (k <= 1 || n <= 1) {
    std::sort(ids.begin(), ids.end());
    out.push_back(std::move(ids));
    return;
  }
  const std::size_t k_lower = k / 2, k_upper = k - k_lower;
  double best_area = std::numeric_limits<double>::infinity();
  int best_axis = 0;
  std::size_t best_cut = k_lower;
  for (int axis = 0; axis < 3; ++axis) {
    sort_on(ids, axis, centre);
    double total = 0;
    for (std::uint32_t s : ids) total += w[s];
    const double target = total * static_cast<double>(k_lower) / static_cast<double>(k);
    double prefix = 0, closest = std::numeric_limits<double>::infinity();
    std::size_t cut = k_lower;
    for (std::size_t i = 0; i < k_lower; ++i) prefix += w[ids[i]];
    for (std::size_t c = k_lower; c <= n - k_upper; prefix += w[ids[c]], ++c) {
      const double off = std::fabs(prefix - target);
      if (off < closest) closest = off, cut = c;
    }
    const double area = box_of(ids, 0, cut, box).surface_area() + box_of(ids, cut, n, box).surface_area();
    if (area < best_area) best_area = area, best_axis = axis, best_cut = cut;
  }
  sort_on(ids, best_axis, centre);
  std::vector<std::uint32_t> lower(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(best_cut));
  std::vector<std::uint32_t> upper(ids.begin() + static_cast<std::ptrdiff_t>(best_cut), ids.end());
  split(std::move(lower), k_lower, box, w, centre, out);
  split(std::move(upper), k_upper, box, w, centre, out);
}

double area_added(const Box<double>& bound, const Box<double>& b) {
  if (b.empty()) return 0;
  Box<double> grown = bound;
  grown.extend(b);
  return grown.surface_area() - bound.surface_area();
}

// Only when fewer spheres than units have a box: a unit with no region may get nothing.
// It takes the lightest sphere (ties: the higher index) of the unit holding the most
// (ties: the lower unit), if that unit keeps one.
void fill_empty_units(Assignment& a, const std::vector<double>& w) {
  for (auto& empty : a.unit) {
    if (!empty.empty()) continue;
    auto donor = std::max_element(a.unit.begin(), a.unit.end(),
                                  [](const auto& x, const auto& y) { return x.size() < y.size(); });
    if (donor->size() < 2) return;
    auto lightest = std::min_element(donor->begin(), donor->end(), [&](std::uint32_t x, std::uint32_t y) {
      return w[x] < w[y] || (w[x] == w[y] && x > y);
    });
    empty.push_back(*lightest);
    donor->erase(lightest);
  }
}

}  // namespace

std::vector<std::vector<std::uint32_t>> spatial_regions(const std::vector<Box<double>>& box,
                                                        const std::vector<double>& w, std::size_t groups) {
  if (box.size() != w.size()) throw std::invalid_argument("spatial_regions: one box and one weight per sphere");
  std::vector<std::uint32_t> ids;
  std::vector<Vec3d> centre(box.size(), Vec3d(0));
  for (std::uint32_t s = 0; s < box.size(); ++s)
    if (!box[s].empty()) {
      ids.push_back(s);
      centre[s] = (box[s].lo + box[s].hi) * 0.5;
    }
  std::vector<std::vector<std::uint32_t>> out;
  const std::size_t k = std::min(groups, ids.size());
  if (k == 0) return out;
  split(std::move(ids), k, box, w, centre, out);
  return out;
}

Assignment assign_spatial(const std::vector<Box<double>>& box, const std::vector<double>& w, std::size_t units,
                          double locality) {
  if (units == 0) throw std::invalid_argument("assign_spatial: no units");
  if (!(locality >= 0 && locality <= 1)) throw std::invalid_argument("assign_spatial: locality outside [0, 1]");
  if (box.size() != w.size()) throw std::invalid_argument("assign_spatial: one box and one weight per sphere");
  for (double x : w)
    if (!(x >= 0 && std::isfinite(x))) throw std::invalid_argument("assign_spatial: a weight is negative or not finite");
  if (locality == 0) return assign_weighted(w, units);

  const auto regions = spatial_regions(box, w, units);
  constexpr std::uint32_t kNoRegion = 0xFFFFFFFFu;
  std::vector<std::uint32_t> home(box.size(), kNoRegion);
  std::vector<Box<double>> bound(units);
  for (std::uint32_t r = 0; r < regions.size(); ++r)
    for (std::uint32_t s : regions[r]) home[s] = r, bound[r].extend(box[s]);

  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  const double mean = total > 0 ? total / static_cast<double>(units) : 1;
  const double area = union_of(box).surface_area();
  const double scene_area = area > 0 ? area : 1;  // no area: every box flat in two axes, nothing grows
  std::vector<std::uint32_t> order(w.size());
  std::iota(order.begin(), order.end(), 0u);
  // Spheres without a box last: they widen nothing and go where the load is least.
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return box[a].empty() != box[b].empty() ? box[b].empty() : w[a] > w[b];
  });

  Assignment a;
  a.unit.resize(units);
  std::vector<double> load(units, 0);
  for (std::uint32_t s : order) {
    std::size_t best = 0;
    double best_score = std::numeric_limits<double>::infinity();
    for (std::size_t u = 0; u < units; ++u) {
      const double over = std::max(0.0, load[u] + w[s] - mean) / mean;
      const double spread = area_added(bound[u], box[s]) / (scene_area * static_cast<double>(units));
      const double score = (1 - locality) * over + locality * spread;
      if (score < best_score || (score == best_score && u == home[s])) best = u, best_score = score;
    }
    a.unit[best].push_back(s);
    load[best] += w[s];
    if (!box[s].empty()) bound[best].extend(box[s]);
  }
  fill_empty_units(a, w);
  for (auto& u : a.unit) std::sort(u.begin(), u.end());
  return a;
}

}  // namespace oprt
