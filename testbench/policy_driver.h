// Decides each frame's assignment of spheres to units for the --balance policy: fixed for
// paper / round_robin / sa_n / spatial; recomputed per frame for view (from the frame's
// camera and lights) and feedback (from the previous frame's measured per-sphere cycles;
// the first frame falls back to sa_n; with --locality F, spatial at F on the measured
// cycles and where the spheres are in the frame, the first frame spatial at F on sa_n's).
// Dynamic assignments keep as much geometry in place as the partition allows; what moves
// is written into object memories over the bus.
// With --replicate (balance/replicate.h) the partition then gains copies of its hottest
// spheres: from sa_n's estimate for the static policies and the first frame, from the
// frame before's measured cycles under feedback, from the view's under view.
// Under routing (--route multicast / ordered) and with --replicate, feedback's measured cost
// of a sphere knows the route: besides its own tests it carries its share of its unit's node tests (each unit's
// node cycles split over its spheres by the rays that reached each, its sphere tests), the
// work a unit does for the rays that enter its bound, which moves with the sphere. (Without
// --replicate feedback stays as it was: on the routing table this cost helped the room at
// K = 8 and hurt the polygons, docs/results.md "Replicated spheres".)
// Feedback's copies also know when the work came in the frame before (FunctionalFrame's
// slices): a unit whose spheres are reached only by the last rows' rays cannot start
// before the GPP issues them (balance/replicate.h).
#pragma once

#include "balance/assign.h"
#include "balance/policy.h"
#include "analytic/engine.h"
#include "arch/arch.h"
#include "ref/scene_geometry.h"

#include <optional>

namespace oprt {

template <typename T>
class PolicyDriver {
 public:
  PolicyDriver(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch, Assignment initial, int width,
               int height);
  // The assignment for frame f; `previous` is the frame before's run (null for the first).
  const Assignment& for_frame(int f, const timing::FrameRun* previous);
  // The run's first assignment: `initial` with copies under --replicate.
  const Assignment& current() const { return current_; }
  bool dynamic() const { return arch_.balance == "feedback" || arch_.balance == "view"; }

 private:
  const Scene& scene_;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  Assignment partition_, current_;  // current_: partition_ with its copies
  std::vector<std::uint64_t> bytes_;
  Assignment with_copies(const Assignment& partition, const std::vector<double>& weight,
                         const timing::FrameRun* previous = nullptr) const;
  std::vector<double> measured_weights(const timing::FrameRun& previous, std::vector<double>* slices = nullptr) const;
  int width_, height_;
};

// The sa_n estimate's costs under an architecture: its sphere, transform and mean triangle
// test, and with --accel bvh each sphere's tree (the weights are then its SAH cost).
template <typename T>
SaNCosts sa_n_costs(const Arch& arch, const SceneGeometry<T>& geometry);

extern template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<float>&);
extern template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<double>&);
extern template class PolicyDriver<float>;
extern template class PolicyDriver<double>;

}  // namespace oprt
