#include "scene/motion.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace oprt {

Quatd axis_angle(const Vec3d& axis, double degrees) {
  const double len = std::sqrt(dot3(axis, axis));
  if (!(len > 0)) return Quatd(1, 0, 0, 0);
  return glm::angleAxis(glm::radians(degrees), axis / len);
}

Affine<double> to_affine(const RigidKey& k) {
  const glm::dmat3 r = glm::mat3_cast(glm::normalize(k.rotate));
  Affine<double> a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a.m[i][j] = r[j][i] * k.scale;  // GLM is column-major
    a.m[i][3] = k.translate[i];
  }
  return a;
}

RigidKey KeyframeMotion::key_at(double frame) const {
  if (keys_.empty()) return {};
  if (frame <= keys_.front().frame) return keys_.front();
  if (frame >= keys_.back().frame) return keys_.back();
  auto hi = std::upper_bound(keys_.begin(), keys_.end(), frame,
                             [](double f, const RigidKey& k) { return f < k.frame; });
  const RigidKey& b = *hi;
  const RigidKey& a = *(hi - 1);
  const double s = (frame - a.frame) / (b.frame - a.frame);
  RigidKey k;
  k.frame = frame;
  k.translate = a.translate + (b.translate - a.translate) * s;
  k.scale = a.scale + (b.scale - a.scale) * s;
  // glm::slerp takes the short way round only if asked: flip b into a's hemisphere.
  Quatd qb = b.rotate;
  if (glm::dot(a.rotate, qb) < 0) qb = -qb;
  k.rotate = glm::slerp(a.rotate, qb, s);
  return k;
}

Affine<double> KeyframeMotion::at(double frame) const { return to_affine(key_at(frame)); }

}  // namespace oprt
