#include "ref/top_tree.h"

#include <algorithm>

namespace oprt {

namespace {
Box<double> widened(Box<double> b, double pad) {
  b.lo -= Vec3d(pad);
  b.hi += Vec3d(pad);
  return b;
}

template <typename T>
Box<double> sphere_box(const Sphere<T>& s) {
  const Vec3d c(s.c);
  const double r = static_cast<double>(s.r);
  return {c - Vec3d(r), c + Vec3d(r)};
}
}  // namespace

template <typename T>
Box<double> world_bounds(const FrameSetup<T>& f, const SceneGeometry<T>& g, std::uint32_t s) {
  if (!f.visible[s]) return {};
  const Affine<double>& m = f.placement[g.object[s]].to_world;
  const Box<T>& l = g.local_box[s];
  Box<double> b;
  for (int k = 0; k < 8; ++k) {
    const Vec3d corner((k & 1 ? l.hi : l.lo).x, (k & 2 ? l.hi : l.lo).y, (k & 4 ? l.hi : l.lo).z);
    b.extend(m.point(corner));
  }
  // The corners' images in double are exact to ~1e-16 relative, far inside the margin.
  b = widened(b, f.margin);
  const Box<double> sb = widened(sphere_box(f.world_sphere[s]), f.margin);
  b.lo = glm::max(b.lo, sb.lo);
  b.hi = glm::min(b.hi, sb.hi);
  return b;
}

template <typename T>
void TopTree::build(const std::vector<std::uint32_t>& unit_spheres, const FrameSetup<T>& f,
                    const SceneGeometry<T>& g) {
  spheres = unit_spheres;
  std::vector<Box<double>> bounds;
  for (std::uint32_t s : spheres) {
    // A sphere hidden at the build frame is placed by its world sphere (defined for every
    // sphere); from the first frame it is shown, the refit gives its real bounds.
    Box<double> b = world_bounds(f, g, s);
    if (b.empty()) b = sphere_box(f.world_sphere[s]);
    bounds.push_back(b);
  }
  // One sphere per leaf: an entered leaf costs its sphere test, the box test above it is
  // what a leaf of several spheres would save. SAH costs in the unit's cycles: a node test
  // against a leaf's sphere test and what follows it.
  BvhBuildParams p;
  p.box_cost = 1;
  p.triangle_cost = 1;
  p.max_leaf = 1;
  BvhBuild b = build_bvh(bounds, p);
  nodes = std::move(b.nodes);
  leaf_sphere.clear();
  for (std::uint32_t k : b.order) leaf_sphere.push_back(spheres[k]);
}

template <typename T>
void TopTree::refit(const FrameSetup<T>& f, const SceneGeometry<T>& g, const std::vector<std::uint32_t>& entry_of,
                    std::vector<TopNode<T>>& out) {
  std::vector<Box<double>> bounds;
  bounds.reserve(leaf_sphere.size());
  for (std::uint32_t s : leaf_sphere) bounds.push_back(world_bounds(f, g, s));
  refit_bvh(nodes, bounds);
  out.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const BvhNode<double>& n = nodes[i];
    TopNode<T>& r = out[i];
    // Rounded outward: the box in T holds the box in double. An empty box stays empty
    // (lo = +inf, hi = -inf), and no ray enters it.
    r.box = n.box.empty() ? Box<T>{} : round_out<T>(n.box, 0);
    r.leaf = n.leaf();
    r.axis = n.axis;
    r.offset = n.leaf() ? entry_of[leaf_sphere[n.offset]] : n.offset;
    if (r.leaf && r.offset == kNoEntry) r.box = Box<T>{};
  }
}

template Box<double> world_bounds(const FrameSetup<float>&, const SceneGeometry<float>&, std::uint32_t);
template Box<double> world_bounds(const FrameSetup<double>&, const SceneGeometry<double>&, std::uint32_t);
template void TopTree::build(const std::vector<std::uint32_t>&, const FrameSetup<float>&, const SceneGeometry<float>&);
template void TopTree::build(const std::vector<std::uint32_t>&, const FrameSetup<double>&, const SceneGeometry<double>&);
template void TopTree::refit(const FrameSetup<float>&, const SceneGeometry<float>&, const std::vector<std::uint32_t>&,
                             std::vector<TopNode<float>>&);
template void TopTree::refit(const FrameSetup<double>&, const SceneGeometry<double>&,
                             const std::vector<std::uint32_t>&, std::vector<TopNode<double>>&);

}  // namespace oprt
