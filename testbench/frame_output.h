// What every level does with a finished frame: turn its run into FrameStats, write the
// image and the statistics, keep them for tests, and print a line.
#pragma once

#include "analytic/engine.h"
#include "render_job.h"

namespace oprt {

template <typename T>
FrameStats frame_stats(const timing::FrameRun& run, const RenderJob& job, const SceneGeometry<T>& geometry, int frame,
                       double wall_s, const FrameImage& image);

// Writes frame_NNNN.exr / .png and the stats files (if the job writes files), keeps the
// results (if asked), prints the frame's line.
void finish_frame(RenderJob& job, StatsWriter* stats, const FrameStats& fs, FrameImage&& image);

extern template FrameStats frame_stats(const timing::FrameRun&, const RenderJob&, const SceneGeometry<float>&, int,
                                       double, const FrameImage&);
extern template FrameStats frame_stats(const timing::FrameRun&, const RenderJob&, const SceneGeometry<double>&, int,
                                       double, const FrameImage&);

}  // namespace oprt
