// A unit's walk through its tree over its spheres (--top bvh, ref/top_tree.h), in world
// space: the same answer as testing every sphere in register order (traverse.h), with
// different work.
//  - Nearest hit: near child first (by the sign of the ray along the node's split axis), a
//    node entered if its box meets the ray before the unit's nearest hit so far (or the
//    ray's tmax). A node is skipped only when the ray enters it strictly beyond that hit:
//    every point a kernel may report in a sphere lies in its leaf's box (world_bounds), so
//    any hit it holds is at or beyond the entry, and a hit at exactly the same t, which may
//    win the (t, object, prim) tie-break, is not lost. Inside an entered sphere the work is
//    traverse.h's (every triangle, or the sphere's own BVH, against the ray's own tmax), so
//    the hit found in a sphere is the same; the unit's answer is the nearest of them.
//  - Shadow rays: nodes entered before the light (tmax), the walk stops at the first
//    occluder. Which occluder is found first changes with the order, not whether one is.
// Work differs from the flat list: node tests are added, sphere tests are only those of the
// leaves entered, and spheres beyond the nearest hit or the light are never entered.
// A leaf whose sphere is a copy (--replicate) and the ray not its share is passed over
// without its sphere test: the unit compares the ray's share key with the entry's copy
// before the test.
// The box test needs the ray's reciprocal direction: the GPP computes it once per ray and
// sends it with the ray (hw/payloads.h), so the unit charges no set-up for it.
#pragma once

#include "ref/sphere_visit.h"

#include <array>

namespace oprt {

// Walks the unit's tree: enter(entry, nodes_tested) on each entered leaf (the node tests
// since the previous leaf, counted for its visit); it returns true to stop the walk.
// Returns the node tests after the last entered leaf.
template <typename T, typename Limit, typename Enter>
std::uint32_t walk_top(const IuRegisters<T>& regs, const Ray<T>& ray, Limit&& limit, Enter&& enter) {
  const BoxRay<T> br = box_ray(ray);
  std::array<std::uint32_t, kBvhMaxDepth> stack;
  int top = 0;
  std::uint32_t node = 0, nodes = 0;
  for (;;) {
    const TopNode<T>& n = regs.top[node];
    ++nodes;
    if (hit_box(br, n.box, limit())) {
      if (!n.leaf) {
        const bool second_first = br.neg[n.axis];
        stack[top++] = second_first ? node + 1 : n.offset;
        node = second_first ? n.offset : node + 1;
        continue;
      }
      const std::uint32_t tested = nodes;
      nodes = 0;
      if (enter(n.offset, tested)) return 0;
    }
    if (top == 0) return nodes;
    node = stack[--top];
  }
}

// The trailing node tests of a walk, as a visit without a sphere.
template <typename Visit>
void report_trailing_nodes(std::uint32_t nodes, Visit& visit) {
  if (!nodes) return;
  SphereVisit v{kNone, kNone, {}};
  v.nodes_before = nodes;
  visit(v);
}

template <typename T, typename Visit>
HitRecord<T> trace_nearest_top(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, const Ray<T>& ray,
                               Visit&& visit, StageLog* log, std::uint32_t key) {
  HitRecord<T> best;
  std::uint32_t carried = 0;  // node tests before a leaf that is another copy's (not a visit)
  const std::uint32_t trailing =
      walk_top(regs, ray, [&] { return best.valid() ? best.t : ray.tmax; }, [&](std::uint32_t i, std::uint32_t nodes) {
        if (!regs.mine(i, key)) {
          carried += nodes;
          return false;
        }
        SphereVisit v{i, regs.sphere[i], {}};
        v.nodes_before = nodes + carried;
        carried = 0;
        v.work.sphere_tests = 1;
        if (hit_sphere(ray, regs.world[i])) keep_closer(mem, v.sphere, nearest_in_sphere(mem, regs, i, ray, v, log), best);
        visit(v);
        return false;
      });
  report_trailing_nodes(trailing + carried, visit);
  return best;
}

template <typename T, typename Visit>
bool trace_any_top(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, const Ray<T>& ray, Visit&& visit,
                   StageLog* log, std::uint32_t key) {
  bool occluded = false;
  std::uint32_t carried = 0;
  const std::uint32_t trailing =
      walk_top(regs, ray, [&] { return ray.tmax; }, [&](std::uint32_t i, std::uint32_t nodes) {
        if (!regs.mine(i, key)) {
          carried += nodes;
          return false;
        }
        SphereVisit v{i, regs.sphere[i], {}};
        v.nodes_before = nodes + carried;
        carried = 0;
        v.work.sphere_tests = 1;
        if (hit_sphere(ray, regs.world[i])) occluded = any_in_sphere(mem, regs, i, ray, v, log);
        visit(v);
        return occluded;
      });
  report_trailing_nodes(trailing + carried, visit);
  return occluded;
}

// Write unit registers' tree for frame f: rebuild `tree` if the unit's spheres changed
// (returns the nodes built in `built`), then refit it to the frame. Call after regs.load.
// Returns the nodes refitted.
template <typename T>
std::size_t load_top(IuRegisters<T>& regs, TopTree& tree, const std::vector<std::uint32_t>& spheres,
                     const FrameSetup<T>& f, const SceneGeometry<T>& g, std::uint64_t* built = nullptr) {
  if (tree.spheres != spheres || tree.nodes.empty()) {
    tree.build(spheres, f, g);
    if (built) *built += tree.size();
  }
  std::vector<std::uint32_t> entry_of(g.sphere_count(), kNoEntry);
  for (std::uint32_t i = 0; i < regs.size(); ++i) entry_of[regs.sphere[i]] = i;
  tree.refit(f, g, entry_of, regs.top);
  return tree.size();
}

}  // namespace oprt
