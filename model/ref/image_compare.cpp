#include "ref/image_compare.h"

#include "ref/parallel.h"

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
  // Per chunk of pixels, then summed in chunk order: the same bits for any thread count.
  struct Part {
    std::size_t id_mismatches = 0, z_compared = 0;
    double sum2 = 0, max_rel_z = 0;
  };
  constexpr std::size_t kChunk = 4096;
  std::vector<Part> parts(chunk_count(a.size(), kChunk));
  const std::vector<float>* colour[2][3] = {{&a.r, &a.g, &a.b}, {&ref.r, &ref.g, &ref.b}};
  parallel_chunks(a.size(), kChunk, [&](std::size_t c, std::size_t begin, std::size_t end) {
    Part& p = parts[c];
    for (std::size_t i = begin; i < end; ++i) {
      if (a.object[i] != ref.object[i] || a.prim[i] != ref.prim[i]) ++p.id_mismatches;
      for (int k = 0; k < 3; ++k) {
        const double e = static_cast<double>((*colour[0][k])[i]) - static_cast<double>((*colour[1][k])[i]);
        p.sum2 += e * e;
      }
      const double z = a.z[i], zr = ref.z[i];
      if (std::isfinite(z) && std::isfinite(zr) && zr > 0) {
        ++p.z_compared;
        p.max_rel_z = std::max(p.max_rel_z, std::abs(z - zr) / zr);
      }
    }
  });
  double sum2 = 0;
  for (const Part& p : parts) {
    d.id_mismatches += p.id_mismatches;
    d.z_compared += p.z_compared;
    d.max_rel_z = std::max(d.max_rel_z, p.max_rel_z);
    sum2 += p.sum2;
  }
  d.color_rmse = d.pixels ? std::sqrt(sum2 / (3.0 * static_cast<double>(d.pixels))) : 0;
  return d;
}

}  // namespace oprt
