#include "balance/policy_driver.h"

#include "balance/dynamic.h"
#include "balance/partition_quality.h"
#include "balance/replicate.h"
#include "balance/spatial.h"

#include <cmath>

namespace oprt {

PolicyDriver::PolicyDriver(const Scene& scene, PolicyInputs inputs, const Arch& arch, Assignment initial, int width,
                           int height)
    : scene_(scene), in_(std::move(inputs)), arch_(arch), partition_(std::move(initial)), width_(width), height_(height) {
  current_ = arch.replicate ? with_copies(partition_, sa_n_weights(scene, *in_.defs, in_.costs)) : partition_;
}

Assignment PolicyDriver::with_copies(const Assignment& partition, const std::vector<double>& weight,
                                     const MeasuredFrame* previous) const {
  if (!arch_.replicate) return partition;
  ReplicateInputs in;
  in.weight = weight;
  in.bytes = in_.bytes;
  in.capacity = arch_.memory.sram_bytes;
  for (std::uint64_t b : in_.bytes) in.budget += b;
  in.budget = (in.budget + 3) / 4;  // copies: at most a quarter of the scene's geometry
  in.max_copies = arch_.replicate == Arch::kReplicateAuto ? 0 : static_cast<std::size_t>(arch_.replicate);
  // A copy's overhead: the rays sent to a unit for it test its flat list, or walk its tree
  // from the root. A full walk tests a node per level on the way down and its sibling, 1 +
  // 2 log2(spheres + 1) nodes; most of the walk is shared with the rays the unit takes
  // anyway, and what the copy's own rays add was measured at about 30 % of it on the room
  // (docs/results.md, "Replicated spheres"): the estimate takes 0.3 of a full walk.
  in.ray_cycles.resize(partition.units());
  for (std::size_t u = 0; u < partition.units(); ++u) {
    const double n = static_cast<double>(partition.unit[u].size()) + 1;
    in.ray_cycles[u] = arch_.top_tree() ? 0.3 * arch_.costs.node * (1 + 2 * std::log2(n)) : arch_.costs.sphere * n;
  }
  if (previous) in.reach = previous->sphere_tests;
  if (previous && !previous->sphere_slices.empty()) {
    // The GPP's issue time in the frame before: its router's and its own per-ray cycles.
    in.slices = previous->slices;
    measured_weights(*previous, &in.weight_slices);
    in.issue = static_cast<double>(previous->route_cycles) +
               static_cast<double>(previous->rays) * arch_.gpp.cycles_per_ray;
  }
  return replicate(partition, in);
}

std::vector<double> PolicyDriver::measured_weights(const MeasuredFrame& previous, std::vector<double>* slices) const {
  const std::size_t spheres = sphere_count(), S = previous.slices;
  std::vector<double> w = previous.sphere_cycles;
  const std::vector<double>& reached = previous.sphere_tests;
  if (slices) {
    slices->assign(spheres * S, 0);
    for (std::size_t i = 0; i < spheres * S && i < previous.sphere_slices.size(); ++i)
      (*slices)[i] = static_cast<double>(previous.sphere_slices[i]);
  }
  if (!arch_.routed() || !arch_.replicate) return w;  // --replicate off: feedback as it always was
  // The route: each unit's node tests, split over its spheres by the rays that reached each
  // (a replicated sphere's tests shared evenly by its copies).
  std::vector<double> copies(spheres, 0);
  for (const auto& list : current_.unit)
    for (std::uint32_t s : list) copies[s] += 1;
  for (std::size_t u = 0; u < current_.units() && u < previous.unit_node_cycles.size(); ++u) {
    const double node = static_cast<double>(previous.unit_node_cycles[u]);
    if (node == 0 || current_.unit[u].empty()) continue;
    double total = 0;
    for (std::uint32_t s : current_.unit[u]) total += reached[s] / copies[s];
    for (std::uint32_t s : current_.unit[u]) {
      const double part = total > 0 ? (reached[s] / copies[s]) / total : 1.0 / static_cast<double>(current_.unit[u].size());
      w[s] += node * part;
      if (slices && (u + 1) * S <= previous.unit_node_slices.size())
        for (std::size_t i = 0; i < S; ++i)
          (*slices)[s * S + i] += part * static_cast<double>(previous.unit_node_slices[u * S + i]);
    }
  }
  return w;
}

const Assignment& PolicyDriver::for_frame(int f, const MeasuredFrame* previous) {
  if (!dynamic()) return current_;
  std::vector<double> w;
  if (arch_.balance == "feedback") {
    if (!previous) return current_;  // the first frame: sa_n, the initial assignment
    w = measured_weights(*previous);
  } else {
    const ViewFrame view = in_.view(f);
    ViewCostModel m;
    m.sphere_cycles = arch_.costs.sphere;
    m.transform_cycles = arch_.kernel_costs().transform;
    // Most tests exit early: the mean of the stage costs is a fair single number.
    m.triangle_cycles = 0;
    for (auto c : arch_.kernel_costs().tri_stage) m.triangle_cycles += c / double(kTriStages);
    w = view_weights(view.world, view.triangles, view.camera, width_, height_, view.lights, m);
  }
  // With a locality, feedback re-partitions by where the spheres are in this frame.
  const Assignment next = arch_.balance == "feedback" && arch_.locality
                              ? assign_spatial(sphere_world_boxes(scene_, *in_.defs, f), w, partition_.units(), *arch_.locality)
                              : assign_weighted(w, partition_.units());
  partition_ = keep_in_place(next, partition_, in_.bytes);
  current_ = with_copies(partition_, w, arch_.balance == "feedback" ? previous : nullptr);
  return current_;
}

}  // namespace oprt
