// How an object (or the camera) moves: a function from frame number to placement.
// Each scene format brings its own curves (linear/slerp keyframes here, Kochanek-Bartels
// splines for BART, sampled channels for glTF); they all answer the same question.
#pragma once

#include "geom/affine.h"

#include <memory>
#include <vector>

#include <glm/gtc/quaternion.hpp>

namespace oprt {

using Quatd = glm::qua<double, glm::defaultp>;

class Motion {
 public:
  virtual ~Motion() = default;
  // local -> world at a (possibly fractional) frame.
  virtual Affine<double> at(double frame) const = 0;
  // False when at() is the same for every frame (lets the engine skip re-sending).
  virtual bool animated() const = 0;
  // Whether the object takes part in the frame at all (BART's visibility keys). A hidden
  // object's spheres are left out of the units' registers for that frame.
  virtual bool visible(double /*frame*/) const { return true; }
};
using MotionPtr = std::shared_ptr<const Motion>;

class StaticMotion final : public Motion {
 public:
  explicit StaticMotion(const Affine<double>& m) : m_(m) {}
  Affine<double> at(double) const override { return m_; }
  bool animated() const override { return false; }

 private:
  Affine<double> m_;
};

// One key of a rigid motion: scale first, then rotate, then translate (M = T R S).
struct RigidKey {
  double frame = 0;
  Vec3d translate{0};
  Quatd rotate{1, 0, 0, 0};
  double scale = 1;
};
Affine<double> to_affine(const RigidKey& k);

// Keys sorted by frame: translation and scale linear, rotation slerp (shortest arc);
// before the first key and after the last the motion holds (clamps).
class KeyframeMotion final : public Motion {
 public:
  explicit KeyframeMotion(std::vector<RigidKey> keys) : keys_(std::move(keys)) {}
  Affine<double> at(double frame) const override;
  RigidKey key_at(double frame) const;
  bool animated() const override { return keys_.size() > 1; }

 private:
  std::vector<RigidKey> keys_;
};

// first(frame) applied after second(frame): world = outer * inner.
class ComposedMotion final : public Motion {
 public:
  ComposedMotion(MotionPtr outer, MotionPtr inner) : outer_(std::move(outer)), inner_(std::move(inner)) {}
  Affine<double> at(double f) const override { return outer_->at(f) * inner_->at(f); }
  bool animated() const override { return outer_->animated() || inner_->animated(); }
  bool visible(double f) const override { return outer_->visible(f) && inner_->visible(f); }

 private:
  MotionPtr outer_, inner_;
};

Quatd axis_angle(const Vec3d& axis, double degrees);

}  // namespace oprt
