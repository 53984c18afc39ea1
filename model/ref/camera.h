// Primary rays of the pinhole camera (scene format: docs/scene-format.md). Computed in
// double, rounded to T: the same bits in the reference and in the GPP model.
#pragma once

#include "geom/ray.h"
#include "scene/scene.h"

#include <cmath>

namespace oprt {

class CameraRays {
 public:
  CameraRays(const Camera& c, int width, int height) : width_(width), height_(height) {
    eye_ = c.eye;
    w_ = glm::normalize(c.eye - c.target);          // points backwards
    u_ = glm::normalize(cross3(c.up, w_));          // right
    v_ = cross3(w_, u_);                            // up
    tan_half_ = std::tan(c.fov_y_deg * 3.14159265358979323846 / 360.0);
    aspect_ = static_cast<double>(width) / height;
  }

  // Pixel (x, y), y = 0 the top row, through its centre; unit direction.
  template <typename T>
  Ray<T> ray(int x, int y) const {
    const double sx = (2 * (x + 0.5) / width_ - 1) * tan_half_ * aspect_;
    const double sy = (1 - 2 * (y + 0.5) / height_) * tan_half_;
    const Vec3d d = glm::normalize(u_ * sx + v_ * sy - w_);
    return {Vec3<T>(eye_), Vec3<T>(d), kInf<T>};
  }

 private:
  int width_, height_;
  Vec3d eye_, u_, v_, w_;
  double tan_half_, aspect_;
};

}  // namespace oprt
