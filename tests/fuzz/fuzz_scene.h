// What a fuzz target does with a scene that loaded: everything `oprt render` does before the
// simulation (bounding spheres, the engine's geometry, frame set-up), and a 3x3 reference
// frame at the first and last frame, so a scene that loads but breaks a later stage is found.
#pragma once

#include "balance/spheres.h"
#include "ref/reference.h"
#include "scene/load.h"
#include "scene/scene.h"

namespace oprt::fuzz {

// The fuzz targets' SceneLimits::triangles (load.h: "fuzz targets lower the triangle limit to
// stay within their memory"). The real 2^25 lets a fuzzer's plane of 13.5 M triangles load and
// its bounding spheres take 2.3 GB under ASan, past libFuzzer's 2 GB; that is the size of the
// scene, not a fault of the loader.
constexpr std::uint64_t kTriangleLimit = std::uint64_t{1} << 20;

inline void exercise(const Scene& scene) {
  const SceneGeometry<float> g = build_geometry<float>(scene, make_spheres(scene, 1));
  render_reference(scene, g, 0, 3, 3);
  const int last = scene.frame_count - 1;
  if (last > 0) {
    check_motions(scene, last, last);  // as the renderers do for the frames asked for
    render_reference(scene, g, last, 3, 3);
  }
}

}  // namespace oprt::fuzz
