#include "scene/gltf_motion.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace oprt {

namespace {
Quatd quat_at(const double* v) {  // glTF order x, y, z, w
  Quatd q;
  q.x = v[0];
  q.y = v[1];
  q.z = v[2];
  q.w = v[3];
  return q;
}

void normalise4(double* v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
  if (n > 0)
    for (int i = 0; i < 4; ++i) v[i] /= n;
  else
    v[0] = v[1] = v[2] = 0, v[3] = 1;  // unreachable for checked keys; stay a rotation
}
}  // namespace

void GltfSampler::evaluate(double t, double* out) const {
  const std::size_t n = times.size();
  const int w = width;
  // Index of a key's value in `values`: CUBICSPLINE keeps (in, value, out) triples.
  const std::size_t stride = interpolation == Interpolation::cubic_spline ? 3 * w : w;
  const std::size_t value_at = interpolation == Interpolation::cubic_spline ? w : 0;
  auto key = [&](std::size_t k) { return values.data() + k * stride + value_at; };
  if (n == 0) return;
  if (n == 1 || t <= times.front() || t >= times.back()) {
    const double* v = key(t >= times.back() ? n - 1 : 0);
    std::copy(v, v + w, out);
    if (rotation) normalise4(out);
    return;
  }
  // times[k] <= t < times[k + 1]
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const double t0 = times[k], t1 = times[k + 1], dt = t1 - t0;
  const double s = (t - t0) / dt;
  const double* a = key(k);
  const double* b = key(k + 1);
  switch (interpolation) {
    case Interpolation::step:
      std::copy(a, a + w, out);
      break;
    case Interpolation::linear:
      if (rotation) {
        // Shortest arc: glm::slerp goes the long way unless b is in a's hemisphere.
        const Quatd qa = quat_at(a);
        Quatd qb = quat_at(b);
        if (glm::dot(qa, qb) < 0) qb = -qb;
        const Quatd q = glm::slerp(qa, qb, s);
        out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
      } else {
        for (int i = 0; i < w; ++i) out[i] = a[i] + (b[i] - a[i]) * s;
      }
      break;
    case Interpolation::cubic_spline: {
      // Cubic Hermite (glTF spec, appendix C): tangents are per second, scaled by dt.
      const double* b_out = a + w;       // out-tangent of key k
      const double* a_in = b - w;        // in-tangent of key k + 1
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s;
      const double h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      for (int i = 0; i < w; ++i)
        out[i] = h00 * a[i] + h10 * dt * b_out[i] + h01 * b[i] + h11 * dt * a_in[i];
      break;
    }
  }
  if (rotation) normalise4(out);
}

Affine<double> trs_affine(const Vec3d& t, const Quatd& r, const Vec3d& s) {
  const glm::dmat3 m = glm::mat3_cast(glm::normalize(r));
  Affine<double> a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a.m[i][j] = m[j][i] * s[j];  // GLM is column-major; S scales columns
    a.m[i][3] = t[i];
  }
  return a;
}

Affine<double> GltfLocal::at_time(double seconds) const {
  if (matrix) return *matrix;
  Vec3d t = translation, s = scale;
  Quatd r = rotation;
  double v[4];
  if (translation_channel) translation_channel->evaluate(seconds, v), t = Vec3d(v[0], v[1], v[2]);
  if (rotation_channel) rotation_channel->evaluate(seconds, v), r = quat_at(v);
  if (scale_channel) scale_channel->evaluate(seconds, v), s = Vec3d(v[0], v[1], v[2]);
  return trs_affine(t, r, s);
}

GltfChainMotion::GltfChainMotion(const std::vector<GltfLocal>& chain) {
  for (const GltfLocal& l : chain) {
    animated_ = animated_ || l.animated();
    if (!l.animated() && !chain_.empty() && !chain_.back().animated()) {
      *chain_.back().matrix = *chain_.back().matrix * l.at_time(0);
    } else if (!l.animated()) {
      GltfLocal fixed;
      fixed.matrix = l.at_time(0);
      chain_.push_back(fixed);
    } else {
      chain_.push_back(l);
    }
  }
}

Affine<double> GltfChainMotion::at(double frame) const {
  const double seconds = frame / kGltfFramesPerSecond;
  Affine<double> m = Affine<double>::identity();
  for (const GltfLocal& l : chain_) m = m * l.at_time(seconds);
  return m;
}

MotionPtr make_chain_motion(const std::vector<GltfLocal>& chain) {
  auto m = std::make_shared<GltfChainMotion>(chain);
  if (m->animated()) return m;
  return std::make_shared<StaticMotion>(m->at(0));
}

Camera GltfCameraPath::at(double frame) const {
  const Affine<double> m = node_->at(frame);
  Camera c;
  c.eye = m.translation();
  c.target = c.eye + glm::normalize(m.vector({0, 0, -1}));
  c.up = glm::normalize(m.vector({0, 1, 0}));
  c.fov_y_deg = fov_y_deg_;
  return c;
}

}  // namespace oprt
