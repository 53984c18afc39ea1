// What the GPP computes at the start of each frame from the objects' matrices and writes
// into the intersection units' configuration registers: per sphere its world centre and
// radius, per object its world -> local matrix. Shared by the reference and the model, so
// both test the same rounded numbers.
#pragma once

#include "ref/scene_geometry.h"

namespace oprt {

template <typename T>
struct FrameSetup {
  int frame = 0;
  Kernel kernel = Kernel::moller;       // the units' triangle kernel (shadow-ray offsets)
  Camera camera;
  std::vector<Placement> placement;     // per object, double (the GPP's own copy)
  std::vector<Affine<T>> to_local;      // per object, as the IU registers hold it
  std::vector<Sphere<T>> world_sphere;  // per sphere
  double margin = 0;                    // how far world bounds reach beyond their content, for rounding
  std::vector<char> visible;            // per sphere: its object takes part in this frame
  std::vector<PointLight> lights;       // the scene's lights where they are in this frame
};

// Throws InputError if an object's matrix at this frame is not invertible, or if what the
// units would hold (the world -> local matrix, the world spheres) does not fit precision T.
template <typename T>
FrameSetup<T> setup_frame(const Scene& scene, const SceneGeometry<T>& g, int frame);
// The same from matrices and camera already evaluated (what the GPP receives from the host).
template <typename T>
FrameSetup<T> setup_frame(const Scene& scene, const SceneGeometry<T>& g, int frame,
                          const std::vector<Affine<double>>& to_world, const Camera& camera);

// Every object's local -> world matrix at a frame.
std::vector<Affine<double>> object_matrices(const Scene& scene, int frame);

extern template FrameSetup<float> setup_frame(const Scene&, const SceneGeometry<float>&, int);
extern template FrameSetup<double> setup_frame(const Scene&, const SceneGeometry<double>&, int);
extern template FrameSetup<float> setup_frame(const Scene&, const SceneGeometry<float>&, int,
                                              const std::vector<Affine<double>>&, const Camera&);
extern template FrameSetup<double> setup_frame(const Scene&, const SceneGeometry<double>&, int,
                                               const std::vector<Affine<double>>&, const Camera&);

}  // namespace oprt
