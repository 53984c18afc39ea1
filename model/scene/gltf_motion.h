// glTF 2.0 node animation as oprt motions. A glTF node's local transform is either a fixed
// matrix or translation * rotation * scale, each of T, R, S possibly driven by an animation
// sampler; an object's placement is the product of the local transforms from the scene root
// down to its node (parent * child). Time in seconds maps to frames at kGltfFramesPerSecond.
#pragma once

#include "scene/motion.h"
#include "scene/scene.h"

#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace oprt {

// glTF keys are in seconds; oprt frames are numbered. Frame f shows time f / 30 s.
constexpr double kGltfFramesPerSecond = 30;

// One animation sampler, already read and checked: key times strictly increasing, values
// finite. Before the first key and after the last the value holds (clamps).
struct GltfSampler {
  enum class Interpolation { step, linear, cubic_spline };
  Interpolation interpolation = Interpolation::linear;
  int width = 3;                // components per value: 3 (translation, scale) or 4 (rotation x, y, z, w)
  bool rotation = false;        // LINEAR rotations slerp (shortest arc); results are renormalised
  std::vector<double> times;    // seconds
  // width values per key; CUBICSPLINE stores per key in-tangent, value, out-tangent (3 x width).
  std::vector<double> values;

  // The value at time t (seconds) into out[0 .. width - 1].
  void evaluate(double t, double* out) const;
  double last_time() const { return times.empty() ? 0 : times.back(); }
};
using GltfSamplerPtr = std::shared_ptr<const GltfSampler>;

// One node's local transform. A node with a matrix is never animated (the glTF rule).
struct GltfLocal {
  std::optional<Affine<double>> matrix;
  Vec3d translation{0};
  Quatd rotation{1, 0, 0, 0};
  Vec3d scale{1};
  GltfSamplerPtr translation_channel, rotation_channel, scale_channel;  // null: fixed

  bool animated() const { return translation_channel || rotation_channel || scale_channel; }
  Affine<double> at_time(double seconds) const;
};

// M = T * R * S, R from a unit quaternion.
Affine<double> trs_affine(const Vec3d& t, const Quatd& r, const Vec3d& s);

// The product root * ... * node of a chain of local transforms (root first). Runs of fixed
// transforms are multiplied once, at construction.
class GltfChainMotion final : public Motion {
 public:
  explicit GltfChainMotion(const std::vector<GltfLocal>& chain);
  Affine<double> at(double frame) const override;
  bool animated() const override { return animated_; }
  std::size_t links() const { return chain_.size(); }  // the work of one at()

 private:
  std::vector<GltfLocal> chain_;  // fixed runs folded into single matrix entries
  bool animated_ = false;
};

// The motion of a node given its chain: a StaticMotion when nothing along it moves.
MotionPtr make_chain_motion(const std::vector<GltfLocal>& chain);

// A glTF camera rides its node: the eye is the node's origin, it looks down the node's -Z,
// with +Y up.
class GltfCameraPath final : public CameraPath {
 public:
  GltfCameraPath(MotionPtr node, double fov_y_deg) : node_(std::move(node)), fov_y_deg_(fov_y_deg) {}
  Camera at(double frame) const override;

 private:
  MotionPtr node_;
  double fov_y_deg_;
};

// A light that moves with its node: PointLight::position is where it is at frame 0, and this
// motion translates it to where(frame) (a point light: its node's origin; a directional
// light's stand-in: far out against the node's -Z).
class GltfLightPath final : public Motion {
 public:
  GltfLightPath(std::function<Vec3d(double)> where, const Vec3d& at_frame0)
      : where_(std::move(where)), at0_(at_frame0) {}
  Affine<double> at(double frame) const override { return translate(where_(frame) - at0_); }
  bool animated() const override { return true; }

 private:
  std::function<Vec3d(double)> where_;
  Vec3d at0_;
};

}  // namespace oprt
