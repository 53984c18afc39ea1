// What a unit whose object memory is a cache (cache.h) reads on one sphere visit, with
// addresses. The functional trace keeps each visit's counts, not its addresses; the unit
// walks the visit again when it times it: the same walk (traverse.h, bvh_traverse.h) on the
// same ray and sphere, so the same items in the same order, now with the BVH nodes' indices
// and the triangles' positions. Cost: the visit's functional work once more, in the timed
// part, only for units whose memory is a cache. Plain C++.
#pragma once

#include "arch/arch.h"
#include "timing/cache.h"
#include "ref/bytes.h"
#include "ref/traverse.h"

#include <numeric>

namespace oprt::timing {

// DRAM addresses of the scene's geometry (cache.h): triangles from 0, nodes from node_base.
template <typename T>
struct GeometryAddresses {
  std::uint64_t triangle_bytes = 0, node_bytes = Bytes<T>::node, node_base = 0;
  GeometryAddresses() = default;
  explicit GeometryAddresses(const SceneGeometry<T>& g) : triangle_bytes(g.triangle_bytes()) {
    const std::uint64_t end = std::uint64_t{g.tris.size()} * triangle_bytes;
    node_base = (end + 4095) / 4096 * 4096;
  }
  std::uint64_t triangle(std::uint64_t index) const { return index * triangle_bytes; }
  std::uint64_t node(std::uint64_t index) const { return node_base + index * node_bytes; }
  // Sphere s's geometry as [first byte, end byte) ranges: triangles, then nodes.
  std::pair<std::uint64_t, std::uint64_t> triangles_of(const SceneGeometry<T>& g, std::uint32_t s) const {
    return {triangle(g.first[s]), triangle(g.first[s + 1])};
  }
  std::pair<std::uint64_t, std::uint64_t> nodes_of(const SceneGeometry<T>& g, std::uint32_t s) const {
    return g.has_bvh() ? std::pair{node(g.first_node[s]), node(g.first_node[s + 1])} : std::pair{node(0), node(0)};
  }
};

// Bytes a unit's spheres occupy in object memory (triangles, and nodes with a BVH).
template <typename T>
std::uint64_t assigned_bytes(const SceneGeometry<T>& g, const std::vector<std::uint32_t>& spheres) {
  std::uint64_t b = 0;
  for (std::uint32_t s : spheres) b += g.memory_bytes(s);
  return b;
}

// Does a unit holding `bytes` of geometry need its object memory as a cache?
inline bool memory_is_cache(const Arch& a, std::uint64_t bytes) {
  return a.memory.sram_bytes != 0 && bytes > a.memory.sram_bytes;
}

// The visit of ray `ray` (shadow: any hit; the other kinds: the nearest) to register entry `entry`,
// as the unit makes it, in memory order. Returns its work (the trace's, recomputed).
template <typename T>
WorkCounts visit_stream(const SceneGeometry<T>& g, const IuRegisters<T>& regs, const Ray<T>& ray, RayKind kind,
                        std::uint32_t entry, const GeometryAddresses<T>& at, VisitStream& out) {
  const std::uint32_t s = regs.sphere[entry];
  const Ray<T> local = regs.to_local[entry].ray(ray);
  WorkCounts w;
  out.sphere = s;
  out.bursts.clear();
  if (g.has_bvh()) {
    if (seeks_nearest(kind)) nearest_in_bvh(g, s, local, w, &out.stages, &out.node_ids);
    else any_in_bvh(g, s, local, w, &out.stages, &out.node_ids);
    // Each node is a burst of one; the triangles after a leaf's node are its range.
    std::size_t k = 0;
    std::uint32_t leaf = 0;
    for (std::size_t i = 0; i < out.stages.size();) {
      if (out.stages[i] == kLogNode) {
        leaf = out.node_ids[k++];
        out.bursts.push_back({at.node(leaf), 1, static_cast<std::uint32_t>(at.node_bytes), true});
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < out.stages.size() && out.stages[j] != kLogNode) ++j;
      out.bursts.push_back({at.triangle(g.nodes[leaf].offset), static_cast<std::uint32_t>(j - i),
                            static_cast<std::uint32_t>(at.triangle_bytes), false});
      i = j;
    }
    return w;
  }
  out.stages.resize(g.triangles_in(s));
  if (seeks_nearest(kind))
    nearest_in_block(g.tris, g.first[s], g.first[s + 1], local, w.tri_stage, &w.tri_hits, out.stages.data());
  else
    any_in_block(g.tris, g.first[s], g.first[s + 1], local, w.tri_stage, &w.tri_hits, out.stages.data());
  out.stages.resize(w.tri_tests());  // a shadow ray stops at its first occluder
  if (!out.stages.empty())
    out.bursts.push_back({at.triangle(g.first[s]), static_cast<std::uint32_t>(out.stages.size()),
                          static_cast<std::uint32_t>(at.triangle_bytes), false});
  return w;
}

}  // namespace oprt::timing
