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
// The driver reads no timing and no geometry of its own: what it needs of them comes as
// plain data (MeasuredFrame, filled by timing/measured_frame.h; PolicyInputs, filled by
// ref/balance_inputs.h).
#pragma once

#include "arch/arch.h"
#include "balance/assign.h"
#include "balance/policy.h"
#include "balance/spheres.h"
#include "geom/sphere.h"
#include "scene/scene.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace oprt {

// What feedback reads of the frame before, as it was measured.
struct MeasuredFrame {
  std::vector<double> sphere_cycles;  // per sphere: its busy cycles, every ray kind
  std::vector<double> sphere_tests;   // per sphere: the rays that reached it (its sphere tests), every kind
  // When the work lay in the frame: the pixels in `slices` equal runs; per sphere and slice
  // its busy cycles, per unit and slice its node tests' cycles ([x * slices + slice]).
  std::uint32_t slices = 0;
  std::vector<std::uint64_t> sphere_slices, unit_node_slices;
  std::vector<std::uint64_t> unit_node_cycles;  // per unit: its node tests' cycles (--top bvh)
  std::uint64_t route_cycles = 0;               // the router's
  std::uint64_t rays = 0;                       // the rays the GPP generated
};

// The view policy's frame: each sphere where it is and the triangles it holds, the camera
// and the lights.
struct ViewFrame {
  std::vector<Sphere<double>> world;
  std::vector<std::size_t> triangles;
  Camera camera;
  std::vector<PointLight> lights;
};

// What the driver reads of the scene's spheres.
struct PolicyInputs {
  const std::vector<SphereDef>* defs = nullptr;  // what each sphere bounds
  std::vector<std::uint64_t> bytes;              // object memory each sphere's geometry takes
  SaNCosts costs;                                // the sa_n estimate's costs under the architecture
  std::function<ViewFrame(int frame)> view;      // --balance view: the frame as the GPP sets it up
};

class PolicyDriver {
 public:
  PolicyDriver(const Scene& scene, PolicyInputs inputs, const Arch& arch, Assignment initial, int width, int height);
  // The assignment for frame f; `previous` is what the frame before measured (null for the first).
  const Assignment& for_frame(int f, const MeasuredFrame* previous);
  // The run's first assignment: `initial` with copies under --replicate.
  const Assignment& current() const { return current_; }
  bool dynamic() const { return arch_.balance == "feedback" || arch_.balance == "view"; }

 private:
  const Scene& scene_;
  PolicyInputs in_;
  const Arch& arch_;
  Assignment partition_, current_;  // current_: partition_ with its copies
  Assignment with_copies(const Assignment& partition, const std::vector<double>& weight,
                         const MeasuredFrame* previous = nullptr) const;
  std::vector<double> measured_weights(const MeasuredFrame& previous, std::vector<double>* slices = nullptr) const;
  std::uint32_t sphere_count() const { return static_cast<std::uint32_t>(in_.bytes.size()); }
  int width_, height_;
};

}  // namespace oprt
