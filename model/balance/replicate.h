// Copies of hot spheres on several units (--replicate, issue 27). No assignment of whole
// spheres to single units can split a sphere that most rays reach (the room's floor: one
// quad, a fifth of the frame's work): its unit bounds the frame. A ray-parallel engine can
// split its *rays* instead: keep copies of the sphere's geometry in several units' object
// memories and send each ray to one copy (ref/traverse.h: share_key; ref/route.h), at the
// cost of the copies' memory and of loading them.
//
// The rule (deterministic): start from the partition; the unit with the largest estimated
// load gives a copy of its heaviest sphere per copy (weight over copies, ties: lower index)
// to the least loaded unit that does not hold it and has memory for it (ties: lower unit),
// if that lowers the largest load; else its next sphere; stop when no copy lowers it. A
// sphere with k copies puts weight / k on each of its units. A unit's memory is the
// capacity given, or with none (on-chip memory without a limit) the largest unit's bytes
// under the partition: units are alike, each sized for the largest assignment, and copies
// fill what the others leave unused, never a memory larger than the partition needs.
#pragma once

#include "balance/assign.h"

#include <cstdint>
#include <vector>

namespace oprt {

struct ReplicateInputs {
  std::vector<double> weight;          // per sphere: its estimated cycles, all copies together
  std::vector<double> unit_extra;      // per unit: cycles no sphere accounts for (may be empty)
  std::vector<std::uint64_t> bytes;    // per sphere: its geometry in object memory
  std::uint64_t capacity = 0;          // per unit (0: the largest unit's bytes under the partition)
  std::size_t max_copies = 0;          // of one sphere (0: as many as there are units)
};

// The partition with copies added (each unit's list ascending; a replicated sphere in
// several lists). Throws std::invalid_argument if the sizes differ.
Assignment replicate(const Assignment& partition, const ReplicateInputs& in);

// The copies beyond the first: per replicated sphere its units, ascending.
struct Replica {
  std::uint32_t sphere;
  std::vector<std::uint32_t> units;
};
std::vector<Replica> replicas(const Assignment& a, std::size_t spheres);
// Bytes the copies beyond the first cost, over every unit.
std::uint64_t replica_bytes(const Assignment& a, const std::vector<std::uint64_t>& bytes);

}  // namespace oprt
