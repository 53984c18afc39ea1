// --balance spatial: spheres to units by where they are (issue 21). When a ray goes only to
// the units whose bound it enters, a unit whose spheres lie close together has a small
// bound and receives few rays; a unit whose spheres are scattered over the scene (as the
// load-only sa_n makes them) is entered by almost every ray. The locality F in [0, 1]
// trades one against the other: 1 keeps each unit's spheres together, 0 balances the
// estimated costs alone (exactly sa_n's greedy).
//
// The rule, in two steps:
//  1. Regions. The spheres are split recursively in world space into as many groups as
//     units: a node with k units gives k / 2 to its lower side and the rest to its upper
//     side; on each axis the spheres, sorted by the centres of their boxes (ties: lower
//     index), are cut where the lower side's cost comes closest to k_lower / k of the node's
//     (ties: the earlier cut; each side keeps at least as many spheres as its units), and
//     of the three cuts the one whose two sides' boxes have the least total area wins
//     (ties: the lower axis). Group i, in tree order (lower side first), is unit i's region.
//  2. Placement. The spheres by decreasing cost (ties: lower index), as the greedy of
//     assign_weighted takes them, each to the unit that minimises
//         (1 - F) x over_u  +  F x spread_u
//     over_u: by how much the unit's load would exceed the mean load with the sphere, in
//             mean loads (0 while it stays below);
//     spread_u: by how much the sphere would widen the unit's bound, as the expected fan-out
//             it adds (partition_quality.h) over the number of units: the share of a
//             broadcast it costs (0 in its own region; a unit's bound starts as its region's
//             box and grows with what it is given from elsewhere);
//     ties: the sphere's own region, then the lower unit.
//     So a sphere stays in its region unless that unit is full, and then goes where the
//     load it would add beyond the mean, against F / (1 - F) times the share of units it
//     would add to a ray's fan-out, is least. Both terms are fractions (of the mean load,
//     of the units), so F means the same at any number of units.
// At F = 1 every sphere stays in its region (nothing costs less than nothing); at F = 0 the
// result is assign_weighted's, sa_n's greedy, exactly. Any F > 0 keeps most spheres in their
// regions: the fan-out falls steeply from F = 0 (sa_n scatters every unit over the scene)
// while the balance stays near sa_n's until F nears 1 (docs/results.md, "Spatial assignment").
// No unit is left empty: while a unit holds no sphere, a sphere of its region costs no more
// there than anywhere else, and the tie goes to the region.
// A sphere with an empty box (its bound unknown) belongs to no region, widens nothing and is
// placed after those with a box.
// Deterministic: no ties are left to the order of evaluation.
#pragma once

#include "arch/arch.h"  // kDefaultLocality
#include "balance/assign.h"
#include "geom/bvh.h"

#include <cstdint>
#include <vector>

namespace oprt {

// Step 1: `groups` regions (at most one per sphere with a box), each listed ascending, in
// tree order. Spheres with an empty box are in none.
std::vector<std::vector<std::uint32_t>> spatial_regions(const std::vector<Box<double>>& sphere_box,
                                                        const std::vector<double>& weight, std::size_t groups);

// Both steps; `locality` in [0, 1]. Throws std::invalid_argument for no units, a locality
// outside [0, 1], or sizes that differ.
Assignment assign_spatial(const std::vector<Box<double>>& sphere_box, const std::vector<double>& weight,
                          std::size_t units, double locality);

}  // namespace oprt
