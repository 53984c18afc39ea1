#include "balance/extent_split.h"

#include "balance/split_prims.h"
#include "geom/bounding_sphere.h"
#include "geom/bvh.h"

#include <algorithm>
#include <limits>

namespace oprt {

// The rule. Every ray tests every sphere (9 cycles); a ray that enters a sphere pays a
// transform (19) and a test of each of its N triangles (14.25 on average). Which rays enter
// which sphere depends on the viewpoint, which the split must not assume; as for the sa_n
// weights (policy.h), rays are taken as isotropic random lines through the scene's convex
// hull H, and such a line enters a convex body X inside H with probability A_X / A_H
// (Crofton), at most 1. So a sphere X costs, per ray, on average
//   E(X) = min(1, A_X / A_H) (transform + N_X triangle)
// on top of its sphere test. Splitting a set S into L and R replaces E(S) by E(L) + E(R)
// and adds one sphere test to every ray. The stopping rule:
//   split S into L and R  iff  E(L) + E(R) + sphere < E(S)
// i.e. iff the split lowers the expected cycles per ray (the IUs' total work). A compact
// piece stops at once: its halves have nearly its radius, so E(L) + E(R) > E(S) (each half
// still pays a transform); a group spread over a room splits until each sphere holds one
// compact piece, because a sphere around two distant pieces is entered by many rays that
// miss both. A small sphere stops too: a split can save at most E(S), and once E(S) is
// below one sphere test no split pays. The areas are those of the minimal enclosing
// spheres that the units will hold, in the object's local units (the hull's area is
// divided by the square of the object's stretch at frame 0, which is the same ratio).
//
// The cut. L and R are the two sides of an axis-aligned plane through the triangle
// centroids, the plane chosen on all three axes, at every gap between consecutive
// centroids, to minimise the same cost with each side's sphere area estimated by the
// sphere around its bounding box (area proportional to the box diagonal squared):
//   d_L^2 (transform + N_L triangle) + d_R^2 (transform + N_R triangle)
// (the surface-area heuristic with spheres). It cuts at the gaps between pieces rather
// than through them. The rule is then applied to the chosen cut with the exact spheres;
// when it refuses, S stays one sphere. Top down and greedy: a cut that does not pay by
// itself is not made, even where further cuts below it would have paid together.

namespace {

constexpr double kPi = 3.14159265358979323846;

using Bounds = Box<double>;  // geom/bvh.h

using Item = SplitPrim;

void sort_on(std::vector<Item>& items, int axis) {
  std::sort(items.begin(), items.end(), [axis](const Item& a, const Item& b) {
    return a.centroid[axis] < b.centroid[axis] || (a.centroid[axis] == b.centroid[axis] && a.id < b.id);
  });
}

class Splitter {
 public:
  Splitter(const Mesh& mesh, const ExtentCosts& c) : mesh_(mesh), c_(c) {}

  double sphere_area(const std::vector<Item>& items) const {
    std::vector<Vec3d> pts;
    pts.reserve(3 * items.size());
    for (const Item& it : items)
      for (std::uint32_t v : mesh_.triangles[it.id]) pts.push_back(mesh_.vertices[v]);
    const double r = minimal_sphere(pts).r;
    return 4 * kPi * r * r;
  }

  double entry_cost(double area, std::size_t n) const {
    return std::min(1.0, area / c_.hull_area) * (c_.transform + static_cast<double>(n) * c_.triangle);
  }

  // The cut of the least estimated cost: items sorted on its axis, left = [0, at).
  // 0 if no cut separates two different centroids.
  std::size_t best_cut(std::vector<Item>& items) const {
    const std::size_t n = items.size();
    double best = std::numeric_limits<double>::max();
    int best_axis = -1;
    std::size_t best_at = 0;
    std::vector<Bounds> right(n);
    for (int axis = 0; axis < 3; ++axis) {
      sort_on(items, axis);
      Bounds acc;
      for (std::size_t i = n; i-- > 0;) acc.extend(items[i].box), right[i] = acc;
      acc = Bounds{};
      for (std::size_t at = 1; at < n; ++at) {
        acc.extend(items[at - 1].box);
        if (!(items[at - 1].centroid[axis] < items[at].centroid[axis])) continue;  // not a gap
        const double cost = acc.diagonal2() * (c_.transform + static_cast<double>(at) * c_.triangle) +
                            right[at].diagonal2() * (c_.transform + static_cast<double>(n - at) * c_.triangle);
        if (cost < best) best = cost, best_axis = axis, best_at = at;
      }
    }
    if (best_axis < 0) return 0;
    sort_on(items, best_axis);
    return best_at;
  }

 private:
  const Mesh& mesh_;
  ExtentCosts c_;
};

}  // namespace

std::vector<std::vector<std::uint32_t>> split_by_extent(const Mesh& mesh, const std::vector<std::uint32_t>& prims,
                                                        const ExtentCosts& costs) {
  const Splitter sp(mesh, costs);
  std::vector<Item> all = split_prims(mesh, prims);
  std::vector<std::vector<std::uint32_t>> out;
  struct Node {
    std::vector<Item> items;
    double area;  // of its minimal enclosing sphere
  };
  // Depth first, lower side first: clusters come out in tree order. A stack, not
  // recursion: a chain of ever more distant pieces may be as deep as it is long.
  std::vector<Node> stack;
  const double area = all.empty() ? 0 : sp.sphere_area(all);
  stack.push_back({std::move(all), area});
  while (!stack.empty()) {
    Node node = std::move(stack.back());
    stack.pop_back();
    const std::size_t at = node.items.size() > 1 ? sp.best_cut(node.items) : 0;
    if (at > 0) {
      std::vector<Item> l(node.items.begin(), node.items.begin() + static_cast<std::ptrdiff_t>(at));
      std::vector<Item> r(node.items.begin() + static_cast<std::ptrdiff_t>(at), node.items.end());
      const double area_l = sp.sphere_area(l), area_r = sp.sphere_area(r);
      const double after = sp.entry_cost(area_l, l.size()) + sp.entry_cost(area_r, r.size()) + costs.sphere;
      if (after < sp.entry_cost(node.area, node.items.size())) {
        stack.push_back({std::move(r), area_r});
        stack.push_back({std::move(l), area_l});
        continue;
      }
    }
    std::vector<std::uint32_t> ids;
    ids.reserve(node.items.size());
    for (const Item& it : node.items) ids.push_back(it.id);
    std::sort(ids.begin(), ids.end());
    if (!ids.empty()) out.push_back(std::move(ids));
  }
  return out;
}

}  // namespace oprt
