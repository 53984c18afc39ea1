#include "ref/image_compare.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace oprt {

ImageDifference compare_images(const FrameImage& a, const FrameImage& ref) {
  if (a.width != ref.width || a.height != ref.height)
    throw std::invalid_argument("sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                                " against " + std::to_string(ref.width) + "x" + std::to_string(ref.height));
  ImageDifference d;
  d.pixels = a.size();
  const std::vector<float>* colour[2][3] = {{&a.r, &a.g, &a.b}, {&ref.r, &ref.g, &ref.b}};
  double sum2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.object[i] != ref.object[i] || a.prim[i] != ref.prim[i]) ++d.id_mismatches;
    for (int c = 0; c < 3; ++c) {
      const double e = static_cast<double>((*colour[0][c])[i]) - static_cast<double>((*colour[1][c])[i]);
      sum2 += e * e;
    }
    const double z = a.z[i], zr = ref.z[i];
    if (std::isfinite(z) && std::isfinite(zr) && zr > 0) {
      ++d.z_compared;
      d.max_rel_z = std::max(d.max_rel_z, std::abs(z - zr) / zr);
    }
  }
  d.color_rmse = d.pixels ? std::sqrt(sum2 / (3.0 * static_cast<double>(d.pixels))) : 0;
  return d;
}

}  // namespace oprt
