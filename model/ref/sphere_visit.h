// One intersection unit's registers and the work of one sphere visit, the parts that the flat
// walk over a unit's spheres (ref/traverse.h) and the walk over its tree (ref/top_traverse.h)
// share: the hit record and its total order, the unit's configuration registers, the sphere
// tests of the register file, and what happens inside an entered sphere.
#pragma once

#include "geom/sphere_soa.h"
#include "ref/bvh_traverse.h"
#include "ref/frame_setup.h"
#include "ref/top_tree.h"
#include "ref/work.h"

#include <limits>

namespace oprt {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

template <typename T>
struct HitRecord {
  T t = kInf<T>;
  std::uint32_t object = kNone, prim = kNone, sphere = kNone;
  T u = 0, v = 0;
  bool valid() const { return object != kNone; }
};

template <typename T>
inline bool closer(const HitRecord<T>& a, const HitRecord<T>& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.object != b.object) return a.object < b.object;
  return a.prim < b.prim;
}

// Replicated spheres (--replicate): a sphere may be held by several units, and each ray it
// would receive is handled by exactly one copy. The rule is by pixel quad (2 x 2 pixels): a
// pixel's rays (its primary ray and its shadow rays) all have the key of its quad, and copy
// key mod copies takes them. Quads, not single rays: neighbouring rays walk the same nodes
// and triangles, so a copy's cache (--sram) sees coherent rays; the key is the quad's
// column plus its row, so the copies take diagonal stripes of quads, and any part of the
// image a few quads across is shared evenly, whatever the number of copies.
inline std::uint32_t share_key(int x, int y) {
  return static_cast<std::uint32_t>(x / 2) + static_cast<std::uint32_t>(y / 2);
}
inline std::uint32_t share_copy(std::uint32_t key, std::uint32_t copies) { return key % copies; }

// One unit's configuration registers for a frame.
template <typename T>
struct IuRegisters {
  std::vector<std::uint32_t> sphere;  // global sphere ids, in the unit's test order
  std::vector<Sphere<T>> world;       // per entry: world bounding sphere
  std::vector<Affine<T>> to_local;    // per entry: world -> local of its object
  SphereSoA<T> world_streams;         // `world` again as streams, for the SIMD sphere test
  std::vector<TopNode<T>> top;        // --top bvh: the tree over the entries (empty: flat, ref/top_tree.h)
  // Replicated spheres (--replicate, balance/replicate.h): per entry the number of copies of
  // its sphere and which one this unit holds (empty: no entry is a copy). A ray is this copy's
  // share when share_copy(key, copies) is its copy (mine()).
  std::vector<std::uint32_t> copies, copy;

  std::size_t size() const { return sphere.size(); }
  // Whether entry i's sphere is this unit's to enter for a ray of share key `key`.
  bool mine(std::uint32_t i, std::uint32_t key) const {
    return copies.empty() || copies[i] <= 1 || share_copy(key, copies[i]) == copy[i];
  }
  void load(const FrameSetup<T>& f, const SceneGeometry<T>& g, const std::vector<std::uint32_t>& spheres) {
    sphere.clear();
    world.clear();
    to_local.clear();
    world_streams.clear();
    top.clear();
    copies.clear();
    copy.clear();
    for (std::uint32_t s : spheres) {
      if (!f.visible[s]) continue;  // hidden this frame: the GPP does not write it
      sphere.push_back(s);
      world.push_back(f.world_sphere[s]);
      world_streams.push_back(f.world_sphere[s]);
      to_local.push_back(f.to_local[g.object[s]]);
    }
  }
  // The sphere tests of entries i .. i+n-1 (n <= kLanes<T>): bit j set if the ray hits
  // entry i + j's world sphere (hit_sphere, geom/sphere_soa.h).
  unsigned sphere_hits(const Ray<T>& ray, std::uint32_t i, unsigned n) const {
    return oprt::sphere_hits(world, world_streams, ray, i, n);
  }
};

// Calls f(i, hit) for each entry i of the unit's registers in order, with its sphere test,
// the tests made kLanes<T> at a time; stops after an entry for which f returns true.
template <typename T, typename F>
inline void for_each_sphere_test(const IuRegisters<T>& regs, const Ray<T>& ray, F&& f) {
  const std::uint32_t count = static_cast<std::uint32_t>(regs.size());
  for (std::uint32_t i0 = 0; i0 < count; i0 += kLanes<T>) {
    const unsigned n = count - i0 < kLanes<T> ? count - i0 : kLanes<T>;
    const unsigned hits = regs.sphere_hits(ray, i0, n);
    for (unsigned j = 0; j < n; ++j)
      if (f(i0 + j, ((hits >> j) & 1u) != 0)) return;
  }
}

// What one sphere visit cost: one sphere test, and if it hit, one transform and the tests
// of the sphere's triangles (all of them for a nearest-hit ray; up to the first occluder for
// a shadow ray), in memory order: work.tri_tests() triangles streamed from object memory.
// With a BVH: the box set-up, then nodes and leaves' triangles in the order of the walk.
struct SphereVisit {
  std::uint32_t entry;   // position in the unit's registers
  std::uint32_t sphere;  // global sphere id
  WorkCounts work;
  // If logged, in memory order: per tested triangle its exit stage, and (BVH) kLogNode per
  // node; work.tri_tests() + work.box_tests entries.
  const std::uint8_t* stages = nullptr;
  // --top bvh: nodes of the unit's tree tested since the previous sphere test. A walk that
  // ends with node tests reports them in a last visit with sphere == kNone (no sphere test).
  std::uint32_t nodes_before = 0;
};


// Scratch for logging exit stages in memory order (the memory model's input); pass nullptr
// to trace_* when the memory is ideal.
using StageLog = std::vector<std::uint8_t>;

// Inside entered sphere i of the unit's registers (flat list or tree, top_traverse.h): the
// ray carried into the sphere's local frame, then every triangle or the sphere's BVH
// (ref/bvh_traverse.h); the work and the stage log go to v.
template <typename T>
BlockHit<T> nearest_in_sphere(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, std::uint32_t i,
                              const Ray<T>& ray, SphereVisit& v, StageLog* log) {
  v.work.transforms = 1;
  const std::uint32_t s = v.sphere;
  const Ray<T> local = regs.to_local[i].ray(ray);
  if (mem.has_bvh()) {
    const BlockHit<T> h = nearest_in_bvh(mem, s, local, v.work, log);
    if (log) v.stages = log->data();
    return h;
  }
  std::uint8_t* l = nullptr;
  if (log) {
    log->resize(mem.triangles_in(s));
    v.stages = l = log->data();
  }
  return nearest_in_block(mem.tris, mem.first[s], mem.first[s + 1], local, v.work.tri_stage, &v.work.tri_hits, l);
}
template <typename T>
bool any_in_sphere(const SceneGeometry<T>& mem, const IuRegisters<T>& regs, std::uint32_t i, const Ray<T>& ray,
                   SphereVisit& v, StageLog* log) {
  v.work.transforms = 1;
  const std::uint32_t s = v.sphere;
  const Ray<T> local = regs.to_local[i].ray(ray);
  if (mem.has_bvh()) {
    const bool occluded = any_in_bvh(mem, s, local, v.work, log);
    if (log) v.stages = log->data();
    return occluded;
  }
  std::uint8_t* l = nullptr;
  if (log) {
    log->resize(mem.triangles_in(s));
    v.stages = l = log->data();
  }
  return any_in_block(mem.tris, mem.first[s], mem.first[s + 1], local, v.work.tri_stage, &v.work.tri_hits, l);
}
// The unit's nearest hit so far, given sphere s's.
template <typename T>
void keep_closer(const SceneGeometry<T>& mem, std::uint32_t s, const BlockHit<T>& h, HitRecord<T>& best) {
  if (!h.valid()) return;
  const HitRecord<T> c{h.t, mem.object[s], mem.prim[h.index], s, h.u, h.v};
  if (closer(c, best)) best = c;
}

}  // namespace oprt
