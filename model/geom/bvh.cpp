#include "geom/bvh.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace oprt {

namespace {

struct Builder {
  const std::vector<Box<double>>& bounds;
  const BvhBuildParams& p;
  std::vector<Vec3d> centroid;
  BvhBuild out;

  // Builds the node over items[first, end) (triangle indices); returns its index.
  std::uint32_t build(std::vector<std::uint32_t>& items, std::size_t first, std::size_t end, int depth) {
    out.depth = std::max(out.depth, depth + 1);
    if (depth + 1 > kBvhMaxDepth) throw std::logic_error("build_bvh: tree deeper than the traversal stack");
    const std::size_t n = end - first;
    Box<double> box;
    for (std::size_t i = first; i < end; ++i) box.extend(bounds[items[i]]);
    const auto index = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.push_back({});
    out.nodes[index].box = box;

    // Best split over the three axes: sort by centroid (ties by index), sweep the prefix
    // and suffix areas. Cost of a split: two box tests (the children) plus, per child, the
    // chance a ray through this box enters it (area ratio) times its triangle tests.
    int best_axis = -1;
    std::size_t best_mid = 0;
    double best_cost = kInf<double>;
    const double area = box.surface_area();
    std::vector<std::uint32_t> sorted[3];
    if (n > 1) {
      std::vector<double> right_area(n);
      for (int a = 0; a < 3; ++a) {
        sorted[a].assign(items.begin() + first, items.begin() + end);
        std::sort(sorted[a].begin(), sorted[a].end(), [&](std::uint32_t x, std::uint32_t y) {
          return centroid[x][a] != centroid[y][a] ? centroid[x][a] < centroid[y][a] : x < y;
        });
        if (depth >= p.sah_depth) continue;
        Box<double> acc;
        for (std::size_t i = n; i-- > 1;) {
          acc.extend(bounds[sorted[a][i]]);
          right_area[i] = acc.surface_area();
        }
        acc = Box<double>{};
        for (std::size_t i = 1; i < n; ++i) {  // left = [0, i), right = [i, n)
          acc.extend(bounds[sorted[a][i - 1]]);
          const double cost =
              2 * p.box_cost + p.triangle_cost * (acc.surface_area() * i + right_area[i] * (n - i)) / area;
          if (cost < best_cost) best_cost = cost, best_axis = a, best_mid = i;
        }
      }
    }
    const double leaf_cost = p.triangle_cost * static_cast<double>(n);
    const bool must_split = n > static_cast<std::size_t>(p.max_leaf);
    if (n > 1 && (depth >= p.sah_depth || !(area > 0) || (must_split && !(best_cost < leaf_cost)))) {
      // Object median along the widest centroid spread: bounds the depth (also where no
      // split beats a leaf that is too large, e.g. coincident triangles).
      Box<double> cb;
      for (std::size_t i = first; i < end; ++i) cb.extend(centroid[items[i]]);
      const Vec3d e = cb.hi - cb.lo;
      best_axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
      best_mid = n / 2;
      best_cost = must_split ? 0 : kInf<double>;
    }
    if (n == 1 || (!must_split && leaf_cost <= best_cost)) {
      std::sort(items.begin() + first, items.begin() + end);  // ascending: ties go to the lowest prim
      out.nodes[index].offset = static_cast<std::uint32_t>(out.order.size());
      out.nodes[index].count = static_cast<std::uint16_t>(n);
      out.order.insert(out.order.end(), items.begin() + first, items.begin() + end);
      return index;
    }
    std::copy(sorted[best_axis].begin(), sorted[best_axis].end(), items.begin() + first);
    out.nodes[index].axis = static_cast<std::uint8_t>(best_axis);
    build(items, first, first + best_mid, depth + 1);
    const std::uint32_t second = build(items, first + best_mid, end, depth + 1);
    out.nodes[index].offset = second;
    return index;
  }
};

}  // namespace

BvhBuild build_bvh(const std::vector<Box<double>>& bounds, const BvhBuildParams& p) {
  if (p.max_leaf < 1 || p.max_leaf > 65535) throw std::invalid_argument("build_bvh: max_leaf out of range");
  Builder b{bounds, p, {}, {}};
  if (bounds.empty()) return b.out;
  b.centroid.reserve(bounds.size());
  for (const Box<double>& t : bounds) b.centroid.push_back((t.lo + t.hi) * 0.5);
  std::vector<std::uint32_t> items(bounds.size());
  std::iota(items.begin(), items.end(), 0u);
  b.out.order.reserve(bounds.size());
  b.build(items, 0, items.size(), 0);
  return b.out;
}

void refit_bvh(std::vector<BvhNode<double>>& nodes, const std::vector<Box<double>>& bounds) {
  // Depth-first layout: children follow their parent, so a reverse sweep sees them first.
  for (std::size_t i = nodes.size(); i-- > 0;) {
    BvhNode<double>& n = nodes[i];
    Box<double> b;
    if (n.leaf()) {
      for (std::uint32_t k = n.offset; k < n.offset + n.count; ++k) b.extend(bounds[k]);
    } else {
      b.extend(nodes[i + 1].box);
      b.extend(nodes[n.offset].box);
    }
    n.box = b;
  }
}

}  // namespace oprt
