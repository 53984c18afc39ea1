// Running the oprt command's testbench inside a test: a scene, an architecture, frames and a resolution
// in; every frame's image and statistics out, as oprt render makes them (no files).
#pragma once

#include "balance/policy.h"
#include "ref/reference.h"
#include "scene/load.h"
#include "testbench.h"

#include <string>

namespace oprt::test {

inline std::string scene_path(const std::string& name) { return std::string(OPRT_SOURCE_DIR) + "/scenes/" + name; }

struct Run {
  RenderJob job;
  std::vector<SphereDef> spheres;
};

template <typename T>
Run simulate_scene(const Scene& scene, const Arch& arch, FrameRange frames, int width, int height,
                   const std::string& vcd = "") {
  Run r;
  r.spheres = make_spheres(scene, arch.subdivide, split_rule_named(arch.split_rule),
                           object_split_named(arch.split, scene.source));  // as oprt render
  r.job.scene = &scene;
  r.job.arch = arch;
  r.job.frames = frames;
  r.job.width = width;
  r.job.height = height;
  r.job.vcd_path = vcd;
  r.job.write_files = false;
  r.job.keep_results = true;
  r.job.assignment = static_assignment(arch.balance, scene, r.spheres, units_for(r.spheres.size(), arch.ius));
  SceneGeometry<T> g = build_geometry<T>(scene, r.spheres, arch.kernel, accel_named(arch.accel));
  simulate<T>(r.job, g);
  return r;
}

}  // namespace oprt::test
