// What the hardware stores and moves, in bytes, and the frame's rays as the GPP issues them.
// Plain C++: the functional trace counts the bytes each visit streams, the SystemC modules
// charge the bus and the memories these sizes, and the analytic level and the cost model use
// the same ones.
#pragma once

#include "geom/bvh.h"
#include "geom/triangle_soa.h"
#include "ref/traverse.h"

#include <cstdint>
#include <vector>

namespace oprt {

// Bytes per item as the hardware stores and moves them, in precision T.
template <typename T>
struct Bytes {
  static constexpr unsigned ray = 8 + 7 * sizeof(T);                   // id, kind, o, d, tmax
  // --top bvh: the ray also carries its reciprocal direction, computed once by the GPP for
  // every unit's node tests (ref/top_traverse.h)
  static constexpr unsigned ray_with_reciprocal = ray + 3 * sizeof(T);
  static constexpr unsigned ray_bytes(bool top) { return top ? ray_with_reciprocal : ray; }
  static constexpr unsigned nearest_answer = 12 + 8 + 3 * sizeof(T);   // ray, unit, flags; object, prim; t, u, v
  static constexpr unsigned shadow_answer = 12;                        // ray, unit, occluded
  static constexpr unsigned sphere_config = 4 + 16 * sizeof(T);        // id, centre, radius, 3x4 matrix
  // per triangle, in the kernel's format: Moller v0, e1, e2, n; watertight v0, v1, v2
  static constexpr unsigned triangle(Kernel k) { return triangle_bytes<T>(k); }
  static constexpr unsigned node = BvhNode<T>::kBytes;                 // box, offset, count, axis
  static constexpr unsigned top_node = 6 * sizeof(T) + 8;              // --top bvh: box, child or entry, leaf, axis
  // A pipelined IU's queue entries: a job for the transform unit (ray slot, register
  // entry) and one for the triangle unit (ray slot, sphere, the local ray's o and d).
  static constexpr unsigned transform_job = 8;
  static constexpr unsigned triangle_job = 8 + 6 * sizeof(T);
};

// Rays of the frame in flight, by id. Written by the GPP; units read the ray a FIFO entry
// names. A nearest-hit ray keeps the traced hit (the GPP checks the units' merged answer
// against it) and the rays its hit spawns, which the GPP issues once it has shaded the hit:
// ids [id + first_child, id + first_child + children) (ref/frame_trace.h).
template <typename T>
struct RayRecord {
  Ray<T> ray;
  RayKind kind = RayKind::primary;
  std::uint8_t depth = 0;      // bounces from the camera (a shadow ray: its hit's)
  std::uint32_t children = 0;
  std::uint32_t pixel = 0;
  std::uint32_t first_child = 0;
  std::uint32_t object = kNone, prim = kNone;  // the traced nearest hit (kNone: a miss, or a shadow ray)
  float t = 0;
  bool hit() const { return object != kNone; }
};

}  // namespace oprt
