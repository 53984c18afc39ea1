// A unit's tree over its own spheres (`--top bvh`): a bounding-volume hierarchy in world
// space whose leaves are the unit's spheres, one per leaf, so that a ray skips whole groups
// of spheres with one test instead of testing every sphere (the flat list, `--top flat`).
//
// Nodes are axis-aligned boxes, not spheres:
//  - a box test yields the distance at which the ray enters the box, so a node entered
//    beyond the unit's nearest hit so far, or beyond a shadow ray's light, is skipped (the
//    limit of the slab test, geom/bvh.h); a sphere test only says "the line meets it";
//  - a leaf's box is the world bounds of its sphere's triangles, which for flat, axis-aligned
//    parts (a room's walls and floor, split by --subdivide) is far tighter than the sphere
//    that bounds them: rays that pass such a part's sphere but not the part never reach it;
//  - its test (13 cycles, arch/cycle_schedule.cpp) is cheaper than the sphere test the model
//    runs (14), and the reciprocal direction it needs is computed once per ray by the GPP
//    and sent with the ray, not once per unit;
//  - the refit is a union of boxes per interior node; bounding two spheres by a sphere is
//    as cheap but grows the radius level by level.
// A leaf that is entered still has its sphere tested (the paper's entry test) before the
// ray is carried into the local frame.
//
// The topology is built (surface area heuristic, geom/bvh.h) when the unit's spheres
// change, from their world bounds at that frame; every frame after that only the boxes are
// recomputed from the new matrices (a refit, by the GPP: no rebuild per frame).
#pragma once

#include "geom/bvh.h"
#include "ref/frame_setup.h"

#include <cstdint>
#include <vector>

namespace oprt {

// One node as the unit's registers hold it.
template <typename T>
struct TopNode {
  Box<T> box;                // world space
  std::uint32_t offset = 0;  // interior: second child (the first follows); leaf: register entry
  bool leaf = false;
  std::uint8_t axis = 0;     // interior: split axis (near child first along it)
};

// World bounds of sphere s at a frame, conservative for every point a kernel may report in
// it: its local box (scene_geometry.h) carried into world space, intersected with the box
// of its world sphere, both widened by the frame's rounding margin (frame_setup.h: the
// world -> local transform and the rounded centre err by a few ulps of the scene's
// magnitude, which the margin covers). Empty for a sphere hidden this frame.
template <typename T>
Box<double> world_bounds(const FrameSetup<T>& f, const SceneGeometry<T>& g, std::uint32_t s);

// The topology of one unit's tree and the spheres it was built for.
struct TopTree {
  std::vector<std::uint32_t> spheres;  // the unit's spheres it was built for
  std::vector<BvhNode<double>> nodes;  // depth first; a leaf's offset indexes `leaf_sphere`
  std::vector<std::uint32_t> leaf_sphere;

  std::size_t size() const { return nodes.size(); }
  // Build over `spheres` from their bounds at frame f (hidden ones by their world sphere).
  template <typename T>
  void build(const std::vector<std::uint32_t>& spheres, const FrameSetup<T>& f, const SceneGeometry<T>& g);
  // Recompute every box for frame f and write the nodes as registers: a leaf names the
  // register entry of its sphere (entry_of[sphere], kNoEntry if not written this frame).
  template <typename T>
  void refit(const FrameSetup<T>& f, const SceneGeometry<T>& g, const std::vector<std::uint32_t>& entry_of,
             std::vector<TopNode<T>>& out);
};

constexpr std::uint32_t kNoEntry = 0xFFFFFFFFu;

extern template Box<double> world_bounds(const FrameSetup<float>&, const SceneGeometry<float>&, std::uint32_t);
extern template Box<double> world_bounds(const FrameSetup<double>&, const SceneGeometry<double>&, std::uint32_t);
extern template void TopTree::build(const std::vector<std::uint32_t>&, const FrameSetup<float>&,
                                    const SceneGeometry<float>&);
extern template void TopTree::build(const std::vector<std::uint32_t>&, const FrameSetup<double>&,
                                    const SceneGeometry<double>&);
extern template void TopTree::refit(const FrameSetup<float>&, const SceneGeometry<float>&,
                                    const std::vector<std::uint32_t>&, std::vector<TopNode<float>>&);
extern template void TopTree::refit(const FrameSetup<double>&, const SceneGeometry<double>&,
                                    const std::vector<std::uint32_t>&, std::vector<TopNode<double>>&);

}  // namespace oprt
