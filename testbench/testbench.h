// The SystemC testbench of `oprt render`: one thread that, per frame, evaluates the scene's
// animation, sends the frame's matrices to the engine's GPP, waits for the frame to
// complete, and collects the image, the per-unit cycles and the trace.
#pragma once

#include "hw/engine.h"
#include "render_job.h"

#include <chrono>
#include <functional>
#include <memory>

namespace oprt {

// Build the engine for `job` and run every frame; returns when done. Must be called where
// SystemC may elaborate (sc_main). Throws on failure.
// The geometry's deforming objects (if any) are updated before each frame.
template <typename T>
void simulate(RenderJob& job, SceneGeometry<T>& geometry);

extern template void simulate<float>(RenderJob&, SceneGeometry<float>&);
extern template void simulate<double>(RenderJob&, SceneGeometry<double>&);

}  // namespace oprt
