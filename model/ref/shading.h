// What the GPP does with a primary ray's nearest hit: Phong shading with one shadow ray
// per light that faces the surface. Split in two halves because in the hardware the shadow
// rays travel through the intersection units between them. Shading runs in double (the
// GPP is a general-purpose processor); the rays it emits are rounded to T.
#pragma once

#include "ref/traverse.h"

#include <vector>

namespace oprt {

// The world point and unit geometric normal (not yet turned towards the viewer) at a hit
// on an object's triangle, from the hit's barycentrics, in double; and the triangle's
// local vertices (for the shadow-ray offset).
struct SurfacePoint {
  Vec3d p, n;
  Vec3d a, b, c;
};
SurfacePoint surface_point(const Object& obj, const Placement& placement, std::uint32_t prim, double u, double v);

template <typename T>
struct ShadeState {
  Vec3d color{0};                 // ambient term, then the visible lights added in order
  std::vector<Vec3d> light_term;  // per shadow ray issued, its light's contribution
};

template <typename T>
class Shader {
 public:
  Shader(const Scene& scene, const FrameSetup<T>& frame) : scene_(scene), frame_(frame) {}

  // Shade a primary hit; appends the shadow rays it needs (light order) to `shadow`.
  ShadeState<T> prepare(const Ray<T>& primary, const HitRecord<T>& hit, std::vector<Ray<T>>& shadow) const;
  // Final colour once every shadow ray of the pixel has an answer.
  Vec3d finish(const ShadeState<T>& s, const std::uint8_t* occluded) const;
  Vec3d background() const { return scene_.background; }

 private:
  const Scene& scene_;
  const FrameSetup<T>& frame_;
};

// The shadow-ray origin: the hit point pushed off the surface along the normal n (facing
// the light) by more than the rounding error with which the intersection kernels, in T,
// can place the point relative to its own triangle's plane. No fixed epsilon: the distance
// is a bound computed from the magnitudes involved (pbrt's OffsetRayOrigin, extended to the
// world -> local round trip the IU performs). For the watertight kernel, whose t carries an
// error that depends on the ray's direction, it adds that kernel's bound on t (pbrt-v4's
// deltaT) for the ray towards the light, l (unit, world). Exposed for tests.
template <typename T>
Vec3d offset_origin(Kernel kernel, const Vec3d& p_world, const Vec3d& n_world, const Vec3d& l_world,
                    const Placement& placement, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2);

// pbrt-v4's conservative bound on the absolute error of t in the watertight test in
// precision T, for the ray o + t d (local frame) against the triangle; 0 if the ray lies in
// the triangle's plane.
template <typename T>
double watertight_t_error(const Vec3d& o, const Vec3d& d, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2);

extern template class Shader<float>;
extern template class Shader<double>;

}  // namespace oprt
