// What the testbench sends the engine each frame (plain C++): the SystemC GPP takes it on its
// host socket, the analytic level as its frame's argument.
#pragma once

#include "geom/affine.h"
#include "ref/camera.h"
#include "ref/image.h"
#include "sample/pixel_sample.h"

#include <vector>

namespace oprt::timing {

// The host's command for one frame (the data of a write to the GPP's host socket).
struct FrameCommand {
  // Set-up before the animation: load every object memory with its unit's geometry (not
  // part of any frame's time or statistics), then return.
  bool setup_only = false;
  int frame = 0;
  std::vector<Affine<double>> to_world;  // per object
  Camera camera;
  int width = 0, height = 0;
  FrameImage* image = nullptr;           // filled in
  const PixelSample* sample = nullptr;   // --sample: the pixels traced (the others marked); null: every one
};

}  // namespace oprt::timing
