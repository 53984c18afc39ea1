// What the GPP does with a nearest hit: Whitted's shading (Whitted, "An improved
// illumination model for shaded display", CACM 23(6), 1980): the local Phong colour with one
// shadow ray per light that faces the surface, plus a reflection ray where the material's
// specular weight is non-zero and a refraction ray where its transmittance is. The colour is
// combined as NFF / AFF define the material (Haines' SPD nff.doc, which BART's AFF extends:
// "Kd is the diffuse component, Ks the specular ... T is transmittance (fraction of
// contribution of the transmitting ray)"):
//   I = kd Ia + sum over visible lights (kd (N.L) + ks (R.V)^shine) Il + Ks I_reflected + T I_refracted
// (Ia the scene's ambient light; Ks the material's `reflect`, T its `transmit`, per channel).
// Split in two halves because in the hardware the spawned rays travel through the
// intersection units between them: shade() emits them, the caller adds up their answers.
// Shading runs in double (the GPP is a general-purpose processor); the rays it emits are
// rounded to T.
#pragma once

#include "ref/traverse.h"

#include <vector>

namespace oprt {

// The world point, unit geometric normal (not yet turned towards the viewer) and unit
// shading normal (the published vertex normals interpolated, or the geometric one) at a hit
// on an object's triangle, from the hit's barycentrics, in double; and the triangle's local
// vertices (for the spawned rays' offsets).
struct SurfacePoint {
  Vec3d p, n, shading;
  Vec3d a, b, c;
};
SurfacePoint surface_point(const Object& obj, const Placement& placement, std::uint32_t prim, double u, double v);

// A ray a hit spawns and what its answer adds to the hit's colour: a shadow ray's light term
// if it is not occluded; a reflection or refraction ray's weight times its own colour.
template <typename T>
struct SpawnedRay {
  Ray<T> ray;
  RayKind kind = RayKind::shadow;
  Vec3d weight{0};
  bool inside = false;  // it travels inside a transmitting object (refraction flips it)
};

template <typename T>
class Shader {
 public:
  // depth: Whitted's recursion bound (-1: the scene's).
  Shader(const Scene& scene, const FrameSetup<T>& frame, int depth = -1)
      : scene_(scene), frame_(frame), depth_(depth >= 0 ? depth : scene.depth) {}

  // Shade a nearest hit of `ray`, a ray `depth` bounces from the camera, travelling inside a
  // transmitting object if `inside`: returns the hit's own colour (the ambient term) and
  // appends the rays it spawns, in this order: a shadow ray per light facing the surface
  // (light order), a reflection ray, a refraction ray (these two only below the depth bound).
  Vec3d shade(const Ray<T>& ray, const HitRecord<T>& hit, int depth, bool inside,
              std::vector<SpawnedRay<T>>& out) const;
  Vec3d background() const { return scene_.background; }
  int max_depth() const { return depth_; }

 private:
  void spawn_secondary(const Ray<T>& ray, const SurfacePoint& sp, const Vec3d& nf, const Vec3d& ns,
                       const Material& mat, const Placement& pl, bool inside, std::vector<SpawnedRay<T>>& out) const;

  const Scene& scene_;
  const FrameSetup<T>& frame_;
  const int depth_;
};

// A spawned ray's origin: the hit point pushed off the surface along the geometric normal n
// (facing the side the ray leaves to: the light, the reflection, the refraction) by more than the rounding error with which the intersection kernels, in T,
// can place the point relative to its own triangle's plane. No fixed epsilon: the distance
// is a bound computed from the magnitudes involved (pbrt's OffsetRayOrigin, extended to the
// world -> local round trip the IU performs). For the watertight kernel, whose t carries an
// error that depends on the ray's direction, it adds that kernel's bound on t (pbrt-v4's
// deltaT) for the ray's direction, l (unit, world). Exposed for tests.
//   Two bounds on the same rounding: `isotropic` charges every axis the largest magnitude
// and stretch (and takes pbrt's deltaT as written, for a unit direction); `tightest` takes
// the smaller of that and a bound per axis (and deltaT for the local direction as it is).
// Shadow rays keep the isotropic one, with which the paper scenes' goldens were made (the
// tightest would move the room's makespans by 3 to 15 cycles in 11.7 M, images unchanged);
// reflection and refraction rays, which bounce between close surfaces, take the tightest
// (in float the isotropic one pushed them through thin glass and past a facing mirror).
enum class OffsetBound { isotropic, tightest };
template <typename T>
Vec3d offset_origin(Kernel kernel, const Vec3d& p_world, const Vec3d& n_world, const Vec3d& l_world,
                    const Placement& placement, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2,
                    OffsetBound bound = OffsetBound::tightest);

// pbrt-v4's conservative bound on the absolute error of t in the watertight test in
// precision T, for the ray o + t d (local frame) against the triangle; 0 if the ray lies in
// the triangle's plane. `unit_direction`: pbrt's form, exact for a unit d, larger than need
// be for a shorter one (OffsetBound::isotropic).
template <typename T>
double watertight_t_error(const Vec3d& o, const Vec3d& d, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2,
                          bool unit_direction = false);

extern template class Shader<float>;
extern template class Shader<double>;

}  // namespace oprt
