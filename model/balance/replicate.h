// Copies of hot spheres on several units (--replicate, issue 27). No assignment of whole
// spheres to single units can split a sphere that most rays reach (the room's floor: one
// quad, a fifth of the frame's work): its unit bounds the frame. A ray-parallel engine can
// split its *rays* instead: keep copies of the sphere's geometry in several units' object
// memories and send each ray to one copy (ref/traverse.h: share_key; ref/route.h), at the
// cost of the copies' memory and of loading them.
//
// The rule (deterministic): start from the partition; the unit with the latest estimated
// finish (its load, or with the work's arrival times the latest part's start plus the work
// after it) gives a copy of its heaviest sphere per copy (weight over copies, ties: lower index)
// to the unit that does not hold it, has memory for it and would finish earliest with it
// (ties: lower unit),
// if that makes the latest finish earlier; else its next sphere; stop when no copy helps. A
// sphere with k copies puts weight / k on each of its units. A unit's memory is the
// capacity given, or with none (on-chip memory without a limit) the largest unit's bytes
// under the partition: units are alike, each sized for the largest assignment, and copies
// fill what the others leave unused, never a memory larger than the partition needs; and
// the copies together stay within a budget (the policy driver's: a quarter of the scene's
// geometry bytes), so that a greedy that gains a little with every copy of a large sphere
// does not double the memory.
#pragma once

#include "balance/assign.h"

#include <cstdint>
#include <vector>

namespace oprt {

struct ReplicateInputs {
  std::vector<double> weight;          // per sphere: its estimated cycles, all copies together
  // Or when that work arrives: `slices` equal parts of the GPP's issue time (`issue`
  // cycles), weight_slices[sphere * slices + i] the sphere's cycles arriving in part i. A
  // unit's finish is then the latest, over the parts, of a part's start plus the work from
  // it on (a unit works through its rays in order): a unit whose rays all come late in
  // the frame finishes late even when its total is the mean. 0 slices: totals only.
  std::size_t slices = 0;
  std::vector<double> weight_slices;
  double issue = 0;
  std::vector<double> unit_extra;      // per unit: cycles no sphere accounts for (may be empty)
  std::vector<std::uint64_t> bytes;    // per sphere: its geometry in object memory
  std::uint64_t capacity = 0;          // per unit (0: the largest unit's bytes under the partition)
  std::uint64_t budget = 0;            // the copies' bytes over every unit, at most (0: no limit)
  std::size_t max_copies = 0;          // of one sphere (0: as many as there are units)
  // What a copy costs beyond its share of the work: per sphere the rays that reach it
  // (reach), and per unit the cycles a ray sent to it for a copy spends before it reaches
  // the copy (ray_cycles: the unit's tree walked from its root, or its flat list). Empty:
  // nothing.
  std::vector<double> reach, ray_cycles;
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
