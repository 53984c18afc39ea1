// oprt compare IMAGE REFERENCE: how far one frame is from a reference frame of the same
// size, as one JSON object on stdout (model/ref/image_compare.h defines the metrics).
#include "commands.h"
#include "ref/image_compare.h"
#include "base/error.h"

#include <cstdio>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace oprt {

int run_compare(const std::string& image_path, const std::string& reference_path) {
  const FrameImage image = read_exr(image_path);
  const FrameImage reference = read_exr(reference_path);
  ImageDifference d;
  try {
    d = compare_images(image, reference);
  } catch (const std::invalid_argument& e) {
    throw InputError(image_path, "", std::string(e.what()) + " (" + reference_path + ")");
  }
  const nlohmann::json out = {
      {"image", image_path},
      {"reference", reference_path},
      {"width", image.width},
      {"height", image.height},
      {"pixels", d.pixels},
      {"id_mismatches", d.id_mismatches},
      {"id_mismatch_fraction", d.pixels ? static_cast<double>(d.id_mismatches) / d.pixels : 0.0},
      {"color_rmse", d.color_rmse},
      {"max_rel_z", d.max_rel_z},
      {"z_compared", d.z_compared}};
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace oprt
