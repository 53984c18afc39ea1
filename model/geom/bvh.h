// A bounding-volume hierarchy per bounding sphere, in the object's local frame: the paper's
// own future work ("spatial subdivision of the primitives inside each bounding region").
// Built once before the animation with the surface area heuristic; stored in object memory
// as pbrt's linear layout (depth first: an interior node's first child follows it, the
// second is at `offset`; a leaf names a contiguous range of triangles); traversed by the
// intersection unit (ref/bvh_traverse.h).
#pragma once

#include "geom/ray.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace oprt {

template <typename T>
struct Box {
  Vec3<T> lo{kInf<T>}, hi{-kInf<T>};

  void extend(const Vec3<T>& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  T surface_area() const {
    if (empty()) return 0;
    const Vec3<T> e = hi - lo;
    return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
  // Its diagonal squared (0 when empty): a sphere around the box has half the diagonal as its
  // radius, so this is proportional to that sphere's area.
  T diagonal2() const {
    if (empty()) return 0;
    const Vec3<T> d = hi - lo;
    return d.x * d.x + d.y * d.y + d.z * d.z;
  }
  bool contains(const Box& b) const {
    return lo.x <= b.lo.x && lo.y <= b.lo.y && lo.z <= b.lo.z && hi.x >= b.hi.x && hi.y >= b.hi.y && hi.z >= b.hi.z;
  }
};

// One node as object memory holds it: its box (6 T), then offset, count and split axis
// (8 bytes): 32 bytes in float, 56 in double.
template <typename T>
struct BvhNode {
  Box<T> box;
  std::uint32_t offset = 0;  // interior: second child (node index); leaf: first triangle
  std::uint16_t count = 0;   // triangles in a leaf; 0 = interior
  std::uint8_t axis = 0;     // interior: the split axis (near child first along it)
  bool leaf() const { return count != 0; }
  static constexpr unsigned kBytes = 6 * sizeof(T) + 8;
};

// Relative costs for the surface area heuristic, in the IU's cycles: a box test and a
// triangle test cost about the same on one adder and one multiplier (hw/cycle_schedule:
// box 14, triangle 4..22, ~14 once a ray is near the triangle). Testing an interior node's
// children costs two box tests. Fixed here, not read from the architecture file: the tree
// is a property of the scene, built once, the same for the reference and every model.
struct BvhBuildParams {
  double box_cost = 1;
  double triangle_cost = 1;
  int max_leaf = 8;         // larger leaves are split even where the SAH prefers a leaf
  int sah_depth = 40;       // below this depth splits are object medians: bounds the depth
};
constexpr int kBvhMaxDepth = 96;  // traversal stack: > sah_depth + log2(any triangle count)

// The tree over n triangles given by their bounds (in double, conservative). `order` lists
// the triangle indices in leaf order (each leaf's in ascending index order); leaf offsets
// index into `order`. Deterministic: ties are broken by triangle index.
struct BvhBuild {
  std::vector<BvhNode<double>> nodes;
  std::vector<std::uint32_t> order;
  int depth = 0;
};
BvhBuild build_bvh(const std::vector<Box<double>>& triangle_bounds, const BvhBuildParams& p = {});

// Recompute every node's box from the triangles' current bounds (indexed as in `order`'s
// positions: bounds[k] bounds the triangle at leaf position k), keeping the topology: for
// non-rigid objects, between frames.
void refit_bvh(std::vector<BvhNode<double>>& nodes, const std::vector<Box<double>>& bounds_in_leaf_order);

// Round a box outward to T, after enlarging it by `pad` on every side.
template <typename T>
Box<T> round_out(const Box<double>& b, double pad) {
  Box<T> r;
  for (int a = 0; a < 3; ++a) {
    const double lo = b.lo[a] - pad, hi = b.hi[a] + pad;
    r.lo[a] = static_cast<T>(lo);
    r.hi[a] = static_cast<T>(hi);
    if (static_cast<double>(r.lo[a]) > lo) r.lo[a] = std::nextafter(r.lo[a], -kInf<T>);
    if (static_cast<double>(r.hi[a]) < hi) r.hi[a] = std::nextafter(r.hi[a], kInf<T>);
  }
  return r;
}

// The ray as the box test uses it: origin, reciprocal direction and its signs, computed
// once per (ray, sphere) after the transform (the IU's "box set-up", arch/cycle_schedule.cpp).
template <typename T>
struct BoxRay {
  Vec3<T> o, inv;
  bool neg[3];
};

template <typename T>
inline BoxRay<T> box_ray(const Ray<T>& r) {
  BoxRay<T> b{r.o, {T(1) / r.d.x, T(1) / r.d.y, T(1) / r.d.z}, {}};
  for (int a = 0; a < 3; ++a) b.neg[a] = b.inv[a] < 0;  // -0 gives -inf: negative, as it should
  return b;
}

// The slack that makes the box test conservative, 1 + 2 gamma(4) rounded to T (1 + 8u in
// float). Why it is enough. Each slab distance is t_c = fl(fl(b - o) * fl(1 / d)): three
// roundings, so t_c = t (1 + th) with |th| <= gamma(3), and the sign of t_c is that of
// the exact t (a difference of two floats is zero only if they are equal). Suppose the
// exact ray segment [0, L] meets the closed box, i.e. every exact near distance n_i <= every
// exact far distance f_j, f_j >= 0 and n_i <= L. Then for a positive n_i
//   n_c <= (1 + g3) n_i <= (1 + g3) f_j <= (1 + g3) / (1 - g3) f_c = (1 + g6) f_c,
// and likewise n_c <= (1 + g6) L (a non-positive n_c is below 0 <= everything); so the
// computed t0 = max(0, n_c) is at most (1 + g6) t1 with t1 = min(L, f_c) >= 0. The final
// product rounds once more: fl(K t1) >= K t1 (1 - u), and K (1 - u) >= (1 + g7)(1 - u)
// >= 1 + g6 for K >= 1 + g7; 1 + 2 g4 exceeds 1 + g7. So t0 <= fl(K t1): the test never
// rejects a box the exact segment meets (barring underflow, |t| < 1e-38 in float).
// pbrt-v4 scales the far distances by 1 + 2 gamma(3) ~ 1 + 6u, which is just short of
// 1 + g6 once the scaling product's own rounding is counted.
template <typename T>
constexpr T kBoxSlack = T(1) + 2 * gamma<T>(4);

// The segment [0, limit] clipped by the box's three slabs: [t0, t1], empty when t0 > t1. A
// direction component of exactly zero gives an infinite reciprocal: a slab the origin lies
// strictly inside gives (-inf, inf), one it lies outside gives an empty interval, and an
// origin exactly on the slab's plane gives 0 * inf = NaN, which the comparisons below
// ignore (the ray lies in the closed slab, which imposes nothing).
template <typename T>
struct SlabSpan {
  T t0, t1;
};
template <typename T>
inline SlabSpan<T> slab_span(const BoxRay<T>& r, const Box<T>& b, T limit) {
  T t0 = 0, t1 = limit;
  for (int a = 0; a < 3; ++a) {
    const T tn = ((r.neg[a] ? b.hi[a] : b.lo[a]) - r.o[a]) * r.inv[a];
    const T tf = ((r.neg[a] ? b.lo[a] : b.hi[a]) - r.o[a]) * r.inv[a];
    if (tn > t0) t0 = tn;
    if (tf < t1) t1 = tf;
  }
  return {t0, t1};
}

// Does the ray's segment [0, limit] meet the box (conservatively, see kBoxSlack)?
template <typename T>
inline bool hit_box(const BoxRay<T>& r, const Box<T>& b, T limit) {
  const SlabSpan<T> s = slab_span(r, b, limit);
  return s.t0 <= s.t1 * kBoxSlack<T>;
}

// The same test, giving the distance at which the ray enters the box (0 if it starts
// inside), or infinity where hit_box says no: what ordering the units a ray visits by
// distance needs (only for the order; skipping a box is hit_box's decision).
template <typename T>
inline T box_entry(const BoxRay<T>& r, const Box<T>& b, T limit) {
  const SlabSpan<T> s = slab_span(r, b, limit);
  return s.t0 <= s.t1 * kBoxSlack<T> ? s.t0 : kInf<T>;
}

}  // namespace oprt
