// What a fuzz target does with a scene that loaded: everything `oprt render` does before the
// simulation (bounding spheres, the engine's geometry, frame set-up), and a 3x3 reference
// frame at the first and last frame, so a scene that loads but breaks a later stage is found.
#pragma once

#include "balance/spheres.h"
#include "ref/reference.h"
#include "scene/load.h"
#include "scene/scene.h"

namespace oprt::fuzz {

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
