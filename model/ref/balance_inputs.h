// What the balance policies read of the scene's geometry (balance/ sees no geometry of its
// own): the sa_n estimate's costs, and the policy driver's inputs (balance/policy_driver.h).
#pragma once

#include "arch/arch.h"
#include "balance/policy.h"
#include "balance/policy_driver.h"
#include "ref/scene_geometry.h"

namespace oprt {

// The sa_n estimate's costs under an architecture: its sphere, transform and mean triangle
// test, and with --accel bvh each sphere's tree (the weights are then its SAH cost).
template <typename T>
SaNCosts sa_n_costs(const Arch& arch, const SceneGeometry<T>& geometry);

// The policy driver's inputs: the spheres' bytes and sa_n costs, and for --balance view
// each frame as the GPP sets it up (setup_frame, on the geometry as it is at that frame:
// `geometry` and `scene` must outlive the driver).
template <typename T>
PolicyInputs policy_inputs(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch);

extern template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<float>&);
extern template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<double>&);
extern template PolicyInputs policy_inputs(const Scene&, const SceneGeometry<float>&, const Arch&);
extern template PolicyInputs policy_inputs(const Scene&, const SceneGeometry<double>&, const Arch&);

}  // namespace oprt
