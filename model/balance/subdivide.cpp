#include "balance/subdivide.h"

#include <algorithm>
#include <numeric>

namespace oprt {

namespace {
Vec3d centroid(const Mesh& m, std::uint32_t t) {
  const Tri& tr = m.triangles[t];
  return (m.vertices[tr[0]] + m.vertices[tr[1]] + m.vertices[tr[2]]) / 3.0;
}

// Split `prims` into k clusters: cut at the centroid median along the axis of largest
// extent, giving each side a share of k proportional to its count, and recurse.
// (A first version; issue 4 revisits the split rule against the sum of SA x N.)
void split(const Mesh& m, std::vector<std::uint32_t> prims, int k,
           std::vector<std::vector<std::uint32_t>>& out) {
  if (k <= 1 || prims.size() <= 1) {
    out.push_back(std::move(prims));
    return;
  }
  Vec3d lo(1e300), hi(-1e300);
  for (std::uint32_t p : prims) {
    const Vec3d c = centroid(m, p);
    lo = glm::min(lo, c);
    hi = glm::max(hi, c);
  }
  const Vec3d ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  const int k_left = k / 2;
  const std::size_t n_left = prims.size() * k_left / k;
  std::nth_element(prims.begin(), prims.begin() + n_left, prims.end(),
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = centroid(m, a)[axis], cb = centroid(m, b)[axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  std::vector<std::uint32_t> left(prims.begin(), prims.begin() + n_left);
  std::vector<std::uint32_t> right(prims.begin() + n_left, prims.end());
  split(m, std::move(left), k_left, out);
  split(m, std::move(right), k - k_left, out);
}
}  // namespace

std::vector<std::vector<std::uint32_t>> subdivide(const Mesh& mesh, int k) {
  std::vector<std::uint32_t> all(mesh.triangles.size());
  std::iota(all.begin(), all.end(), 0u);
  const int clusters = std::min<int>(k, static_cast<int>(all.size()));
  std::vector<std::vector<std::uint32_t>> out;
  split(mesh, std::move(all), clusters, out);
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& c) { return c.empty(); }), out.end());
  for (auto& c : out) std::sort(c.begin(), c.end());
  return out;
}

}  // namespace oprt
