// The geometry as the engine holds it, built once before the animation: per bounding
// sphere its local sphere and its triangles in the kernel's memory format, in precision T.
// The reference renderer reads it directly; the hardware model's object memories hold
// the spheres assigned to each IU.
#pragma once

#include "balance/spheres.h"
#include "geom/bvh.h"
#include "geom/sphere.h"
#include "geom/triangle_soa.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

enum class Precision { single, dual };  // float | double
// What an IU does inside a sphere it enters: test every triangle (the paper's evaluation)
// or traverse the sphere's BVH (geom/bvh.h, ref/bvh_traverse.h).
enum class Accel { brute, bvh };
Accel accel_named(const std::string& name);  // "brute" | "bvh"; throws std::invalid_argument

template <typename T>
struct SceneGeometry {
  std::vector<SphereDef> defs;           // what each sphere bounds (double, for balance)
  std::vector<Sphere<T>> local_sphere;   // per sphere, enclosing its T-rounded triangles
  std::vector<std::uint32_t> object;     // per sphere: its object
  std::vector<std::uint32_t> first;      // per sphere: first triangle in `tris`; size + 1
  TriangleStore<T> tris;                 // grouped by sphere: each sphere's in prim order
                                         // (brute) or in its BVH's leaf order (bvh)
  std::vector<std::uint32_t> prim;       // per stored triangle: index in the object's mesh
  std::vector<char> deforming;           // per sphere: its object's vertices move (BART tpa)
  // With Accel::bvh: per sphere its first node (size + 1; empty for brute), and the nodes,
  // each sphere's depth first from its root; leaf offsets index `tris` directly.
  std::vector<std::uint32_t> first_node;
  std::vector<BvhNode<T>> nodes;
  // Per sphere, in the local frame: the bounds of its triangles, padded as a BVH root is
  // (so that it holds every point a kernel may report), whatever the accel. What the
  // unit's tree over its spheres bounds (--top bvh, ref/top_tree.h).
  std::vector<Box<T>> local_box;

  std::uint32_t sphere_count() const { return static_cast<std::uint32_t>(object.size()); }
  std::uint32_t triangles_in(std::uint32_t s) const { return first[s + 1] - first[s]; }
  bool has_bvh() const { return !first_node.empty(); }
  std::uint32_t nodes_in(std::uint32_t s) const { return has_bvh() ? first_node[s + 1] - first_node[s] : 0; }
  Kernel kernel() const { return tris.kernel; }
  // Bytes one triangle and one node occupy in object memory (the memory model charges
  // transfers), and what a sphere's geometry occupies.
  std::uint32_t triangle_bytes() const { return tris.bytes_per_triangle(); }
  static constexpr std::uint32_t kNodeBytes = BvhNode<T>::kBytes;
  std::uint64_t memory_bytes(std::uint32_t s) const {
    return std::uint64_t{triangles_in(s)} * triangle_bytes() + std::uint64_t{nodes_in(s)} * kNodeBytes;
  }
};

// Throws InputError if a vertex does not fit precision T (a coordinate beyond float's range
// would become infinite).
template <typename T>
SceneGeometry<T> build_geometry(const Scene& scene, std::vector<SphereDef> defs, Kernel kernel = Kernel::moller,
                                Accel accel = Accel::brute);
template <typename T>
SceneGeometry<T> build_geometry(const Scene& scene, std::vector<SphereDef> defs, Accel accel) {
  return build_geometry<T>(scene, std::move(defs), Kernel::moller, accel);
}

// For scenes with non-rigid objects: rewrite the deforming spheres' triangles and local
// spheres for frame f (the clusters, fixed at frame 0, keep their triangles). Between
// frames only. Their BVHs keep their topology and are refitted. Returns the bytes
// rewritten (what object memory receives).
template <typename T>
std::uint64_t update_deforming(SceneGeometry<T>& g, const Scene& scene, int frame);
bool has_deforming(const Scene& scene);

extern template SceneGeometry<float> build_geometry(const Scene&, std::vector<SphereDef>, Kernel, Accel);
extern template SceneGeometry<double> build_geometry(const Scene&, std::vector<SphereDef>, Kernel, Accel);
extern template std::uint64_t update_deforming(SceneGeometry<float>&, const Scene&, int);
extern template std::uint64_t update_deforming(SceneGeometry<double>&, const Scene&, int);

}  // namespace oprt
