#include "ref/balance_inputs.h"

#include "ref/frame_setup.h"

namespace oprt {

template <typename T>
SaNCosts sa_n_costs(const Arch& arch, const SceneGeometry<T>& g) {
  SaNCosts costs;
  costs.sphere = arch.costs.sphere;
  costs.transform = arch.kernel_costs().transform;
  costs.triangle = 0;
  for (auto c : arch.kernel_costs().tri_stage) costs.triangle += c / double(kTriStages);
  costs.box_setup = arch.costs.box_setup;
  costs.box = arch.costs.box;
  if (!g.has_bvh()) return costs;
  costs.bvh.resize(g.sphere_count());  // per sphere its nodes' box areas and leaf sizes
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
    for (std::uint32_t i = g.first_node[s]; i < g.first_node[s + 1]; ++i)
      costs.bvh[s].push_back({static_cast<double>(g.nodes[i].box.surface_area()), g.nodes[i].count});
  return costs;
}

template <typename T>
PolicyInputs policy_inputs(const Scene& scene, const SceneGeometry<T>& g, const Arch& arch) {
  PolicyInputs in;
  in.defs = &g.defs;
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
    in.bytes.push_back(g.memory_bytes(s));
  in.costs = sa_n_costs(arch, g);
  in.view = [&scene, &g](int f) {
    const FrameSetup<T> setup = setup_frame(scene, g, f);
    ViewFrame v;
    for (std::uint32_t s = 0; s < g.sphere_count(); ++s) {
      v.world.push_back({Vec3d(setup.world_sphere[s].c), static_cast<double>(setup.world_sphere[s].r)});
      v.triangles.push_back(g.triangles_in(s));
    }
    v.camera = setup.camera;
    v.lights = setup.lights;
    return v;
  };
  return in;
}

template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<float>&);
template SaNCosts sa_n_costs(const Arch&, const SceneGeometry<double>&);
template PolicyInputs policy_inputs(const Scene&, const SceneGeometry<float>&, const Arch&);
template PolicyInputs policy_inputs(const Scene&, const SceneGeometry<double>&, const Arch&);

}  // namespace oprt
