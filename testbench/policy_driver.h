// Decides each frame's assignment of spheres to units for the --balance policy: fixed for
// paper / round_robin / sa_n; recomputed per frame for view (from the frame's camera and
// lights) and feedback (from the previous frame's measured per-sphere cycles; the first
// frame falls back to sa_n). Dynamic assignments keep as much geometry in place as the
// partition allows; what moves is written into object memories over the bus.
#pragma once

#include "balance/assign.h"
#include "timing/analytic.h"
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
  const Assignment& for_frame(int f, const hw::FrameRun* previous);
  bool dynamic() const { return arch_.balance == "feedback" || arch_.balance == "view"; }

 private:
  const Scene& scene_;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  Assignment current_;
  std::vector<std::uint64_t> bytes_;
  int width_, height_;
};

extern template class PolicyDriver<float>;
extern template class PolicyDriver<double>;

}  // namespace oprt
