// How far one rendered frame is from a reference frame of the same size: what the precision
// and kernel choices cost in image quality (scripts/speed_vs_error, `oprt compare`).
#pragma once

#include "ref/image.h"

#include <cstddef>

namespace oprt {

struct ImageDifference {
  std::size_t pixels = 0;
  std::size_t id_mismatches = 0;  // pixels whose objectId or primId differ (a miss is an id too)
  double color_rmse = 0;          // root mean square of R, G, B differences over every pixel
  double max_rel_z = 0;           // max |Z - Zref| / Zref over pixels with a finite Z in both
  std::size_t z_compared = 0;     // how many pixels that is
};

// Throws std::invalid_argument if the sizes differ.
ImageDifference compare_images(const FrameImage& image, const FrameImage& reference);

}  // namespace oprt
