// Object memory timing under the latency model (plain C++): the functional trace charges
// each sphere visit its stall (functional_frame.cpp), which the SystemC unit and the
// analytic level then read from the trace.
#pragma once

#include <cstdint>

namespace oprt {

// What one sphere visit reads, and what the unit does with it.
struct StreamCosts {
  std::uint32_t latency = 0, bytes_per_cycle = 1;  // the memory
  std::uint32_t triangle_bytes = 0, node_bytes = 0;
  std::uint32_t lead = 0;  // the unit's cycles from the request to its first test: transform
                           // (+ box set-up with a BVH)
  const std::uint32_t* triangle = nullptr;  // cycles per exit stage
  std::uint32_t box = 0;                    // cycles per box test
};

// Stall cycles of one sphere visit under the latency model. `items` is the visit's log in
// memory order (ref/bvh_traverse.h): a triangle's exit stage, or kLogNode (0xFF) for a BVH
// node. Data comes in bursts: a burst requested at time r delivers its item j (0-based) at
//   r + latency + ceil((j + 1) bytes / bytes_per_cycle),
// and a test starts when the unit has finished the previous one and its item has arrived.
//  - The first burst is requested when the sphere test hits, so the transform (the lead)
//    hides up to its own length of latency. Brute force: the sphere's triangles are one
//    burst.
//  - BVH: each node is its own burst and so is each leaf's triangle range. These fetches
//    are dependent: the address of the next node or leaf is known only once the unit has
//    tested the current node's box (or finished the leaf and popped its stack), so each is
//    requested when the previous test ends and pays the full latency. No prefetch of both
//    children and no node cache: the simplest memory a unit could have; a designer would
//    hide much of this, and the stall cycles show how much there is to hide.
// Returns the cycles the unit waited.
std::uint64_t stream_stall(const StreamCosts& c, const std::uint8_t* items, std::uint32_t n);

}  // namespace oprt
