#include "ref/frame_setup.h"

#include "base/error.h"

#include <cmath>

namespace oprt {

namespace {
template <typename T>
const char* precision_name() {
  return sizeof(T) == 4 ? "float precision" : "double precision";
}
}  // namespace

std::vector<Affine<double>> object_matrices(const Scene& scene, int frame) {
  std::vector<Affine<double>> m;
  m.reserve(scene.objects.size());
  for (const Object& o : scene.objects) m.push_back(o.motion->at(frame));
  return m;
}

template <typename T>
FrameSetup<T> setup_frame(const Scene& scene, const SceneGeometry<T>& g, int frame) {
  return setup_frame(scene, g, frame, object_matrices(scene, frame), scene.camera->at(frame));
}

template <typename T>
FrameSetup<T> setup_frame(const Scene& scene, const SceneGeometry<T>& g, int frame,
                          const std::vector<Affine<double>>& to_world, const Camera& camera) {
  FrameSetup<T> f;
  f.frame = frame;
  f.kernel = g.kernel();
  f.camera = camera;
  f.placement.reserve(scene.objects.size());
  f.to_local.reserve(scene.objects.size());
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Affine<double>& m = to_world.at(o);
    auto p = make_placement(m);
    if (!p)
      throw InputError(scene.source, "object " + std::to_string(o) + " (\"" + scene.objects[o].name +
                                         "\") at frame " + std::to_string(frame),
                       why_not_invertible(m));
    f.placement.push_back(*p);
    f.to_local.push_back(p->to_local.cast<T>());
    if (!f.to_local.back().finite())
      throw InputError(scene.source, "object " + std::to_string(o) + " (\"" + scene.objects[o].name +
                                         "\") at frame " + std::to_string(frame),
                       std::string("the inverse of the matrix is beyond the range of ") + precision_name<T>());
  }
  // World spheres. The radius is scaled by the matrix's largest stretch (exact for rotation
  // and uniform scale, conservative for non-uniform scale and shear), then widened by a
  // margin for rounding: every ray origin lies within magnitude M of the world origin (the
  // eye, or a point on an object), and the world sphere test, the world -> local transform
  // in T and the rounded centre each err by a few ulps of M. 64 ulps of M covers the chain
  // with room to spare; a wider sphere only costs culling, a narrower one would lose hits.
  std::vector<Sphere<double>> world(g.sphere_count());
  double magnitude = max_abs_component(f.camera.eye);
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s) {
    const Affine<double>& to_world = f.placement[g.object[s]].to_world;
    const Sphere<T>& l = g.local_sphere[s];
    world[s].c = to_world.point(Vec3d(l.c));
    world[s].r = static_cast<double>(l.r) * max_stretch(to_world);
    magnitude = std::fmax(magnitude, max_abs_component(world[s].c) + world[s].r);
  }
  const double margin = 64 * static_cast<double>(std::numeric_limits<T>::epsilon()) * magnitude;
  f.margin = margin;
  f.world_sphere.resize(g.sphere_count());
  f.lights = scene.lights;
  for (PointLight& l : f.lights) l.position = l.at(frame);
  // Visibility comes with the frame's animation like the matrices (BART's visibility keys).
  f.visible.resize(g.sphere_count());
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
    f.visible[s] = scene.objects[g.object[s]].motion->visible(frame);
  for (std::uint32_t s = 0; s < g.sphere_count(); ++s) {
    f.world_sphere[s].c = Vec3<T>(world[s].c);
    const double r = world[s].r + margin;
    T rt = static_cast<T>(r);
    if (static_cast<double>(rt) < r) rt = std::nextafter(rt, kInf<T>);
    f.world_sphere[s].r = rt;
    if (!all_finite(f.world_sphere[s].c) || !std::isfinite(rt))
      throw InputError(scene.source, "object " + std::to_string(g.object[s]) + " at frame " + std::to_string(frame),
                       std::string("its bounding sphere in world space is beyond the range of ") + precision_name<T>());
  }
  return f;
}

template FrameSetup<float> setup_frame(const Scene&, const SceneGeometry<float>&, int);
template FrameSetup<double> setup_frame(const Scene&, const SceneGeometry<double>&, int);
template FrameSetup<float> setup_frame(const Scene&, const SceneGeometry<float>&, int,
                                       const std::vector<Affine<double>>&, const Camera&);
template FrameSetup<double> setup_frame(const Scene&, const SceneGeometry<double>&, int,
                                        const std::vector<Affine<double>>&, const Camera&);

}  // namespace oprt
