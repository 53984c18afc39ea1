// The intersection unit's walk through one sphere's BVH (geom/bvh.h), in the sphere's local
// frame, after the transform. It finds exactly the hit that testing every triangle of the
// sphere finds (traverse.h), ties included, by construction:
//  - the box test is conservative (geom/bvh.h: kBoxSlack) and the boxes hold every point a
//    kernel may report (ref/scene_geometry.cpp: bvh_pad), so no box on the way to that
//    triangle is rejected while its hit is still the nearest found;
//  - a node is pruned only when its entry distance is strictly beyond the best t found so
//    far *in this sphere*: a node entered at exactly that t may hold a tied hit;
//  - triangles are tested by the block functions on a leaf's contiguous range [first, end),
//    against the ray's own tmax (so each test's exit stage, and cost, is the brute-force
//    one), each leaf in ascending prim order; hits across leaves are merged by (t, prim),
//    the tie-break of traverse.h.
// The walk depends only on the ray and the sphere (never on hits in other spheres or other
// units), so a sphere's work is the same in every assignment of spheres to units and at
// every timing level. Near child first, by the sign of the ray along the node's split axis.
#pragma once

#include "ref/scene_geometry.h"
#include "ref/work.h"

#include <array>
#include <vector>

namespace oprt {

// Memory-order log of one sphere visit for the memory model (ref/memory_timing.h): per item
// a triangle's exit stage (0..3), or kLogNode for a node fetched and box-tested.
constexpr std::uint8_t kLogNode = 0xFF;

inline void log_node(std::vector<std::uint8_t>* log) {
  if (log) log->push_back(kLogNode);
}

// Room in the log for a leaf's triangles; where the block function writes their stages.
inline std::uint8_t* log_leaf(std::vector<std::uint8_t>* log, std::uint32_t count) {
  if (!log) return nullptr;
  log->resize(log->size() + count);
  return log->data() + log->size() - count;
}

// The walk both ray kinds share: near child first, a node entered if its box meets the ray
// before limit() (the ray's extent, or the best hit so far), leaf(node) called on each leaf
// entered; it returns true to stop the walk (a shadow ray's first occluder). `ids`, if
// given, receives the index of every node tested, in order (the addresses a memory model
// needs: timing/visit_stream.h).
template <typename T, typename Limit, typename Leaf>
void walk_bvh(const SceneGeometry<T>& mem, std::uint32_t s, const Ray<T>& ray, WorkCounts& w,
              std::vector<std::uint8_t>* log, Limit&& limit, Leaf&& leaf, std::vector<std::uint32_t>* ids = nullptr) {
  if (log) log->clear();
  if (ids) ids->clear();
  if (mem.nodes_in(s) == 0) return;
  const BoxRay<T> br = box_ray(ray);
  ++w.box_setups;
  std::array<std::uint32_t, kBvhMaxDepth> stack;
  int top = 0;
  std::uint32_t node = mem.first_node[s];
  for (;;) {
    const BvhNode<T>& n = mem.nodes[node];
    ++w.box_tests;
    log_node(log);
    if (ids) ids->push_back(node);
    if (hit_box(br, n.box, limit())) {
      if (!n.leaf()) {
        // The first child holds the lower centroids along the axis: the near side unless
        // the ray runs towards lower values.
        const bool second_first = br.neg[n.axis];
        stack[top++] = second_first ? node + 1 : n.offset;
        node = second_first ? n.offset : node + 1;
        continue;
      }
      if (leaf(n)) return;
    }
    if (top == 0) return;
    node = stack[--top];
  }
}

// Nearest hit in sphere s; `w` gets one box set-up, the box tests and the triangle tests.
template <typename T>
BlockHit<T> nearest_in_bvh(const SceneGeometry<T>& mem, std::uint32_t s, const Ray<T>& ray, WorkCounts& w,
                           std::vector<std::uint8_t>* log, std::vector<std::uint32_t>* ids = nullptr) {
  BlockHit<T> best;
  walk_bvh(mem, s, ray, w, log, [&] { return best.valid() ? best.t : ray.tmax; }, [&](const BvhNode<T>& n) {
    std::uint8_t* l = log_leaf(log, n.count);
    const BlockHit<T> h = nearest_in_block(mem.tris, n.offset, n.offset + n.count, ray, w.tri_stage, &w.tri_hits, l);
    if (h.valid() && (h.t < best.t || (h.t == best.t && mem.prim[h.index] < mem.prim[best.index]))) best = h;
    return false;
  }, ids);
  return best;
}

// Any hit in (0, tmax) in sphere s: stops at the first occluder found.
template <typename T>
bool any_in_bvh(const SceneGeometry<T>& mem, std::uint32_t s, const Ray<T>& ray, WorkCounts& w,
                std::vector<std::uint8_t>* log, std::vector<std::uint32_t>* ids = nullptr) {
  bool occluded = false;
  walk_bvh(mem, s, ray, w, log, [&] { return ray.tmax; }, [&](const BvhNode<T>& n) {
    std::uint8_t* l = log_leaf(log, n.count);
    const std::uint64_t before = w.tri_tests();
    occluded = any_in_block(mem.tris, n.offset, n.offset + n.count, ray, w.tri_stage, &w.tri_hits, l);
    if (occluded && log) log->resize(log->size() - n.count + (w.tri_tests() - before));  // the tests not made
    return occluded;
  }, ids);
  return occluded;
}

}  // namespace oprt
