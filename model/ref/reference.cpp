#include "ref/reference.h"

#include "ref/camera.h"
#include "ref/stop.h"

#include <numeric>

namespace oprt {

WorkCounts FrameWork::total(RayKind k) const {
  WorkCounts w;
  for (const WorkCounts& s : per_sphere[static_cast<int>(k)]) w += s;
  return w;
}

WorkCounts FrameWork::total() const {
  WorkCounts w = total(RayKind::primary);
  w += total(RayKind::shadow);
  return w;
}

template <typename T>
FrameResult render_reference(const Scene& scene, const SceneGeometry<T>& g, int frame, int width, int height) {
  const FrameSetup<T> f = setup_frame(scene, g, frame);
  const CameraRays camera(f.camera, width, height);
  const Shader<T> shader(scene, f);
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  IuRegisters<T> regs;
  regs.load(f, g, all);

  FrameResult out{FrameImage(width, height), FrameWork(g.sphere_count())};
  const AccumulateWork primary_work{out.work.per_sphere[0].data()};
  const AccumulateWork shadow_work{out.work.per_sphere[1].data()};
  std::vector<Ray<T>> shadow;
  std::vector<std::uint8_t> occluded;
  for (int y = 0; y < height; ++y) {
    throw_if_stopped();
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      const Ray<T> ray = camera.ray<T>(x, y);
      ++out.work.rays[0];
      const HitRecord<T> hit = trace_nearest(g, regs, ray, primary_work);
      Vec3d color = shader.background();
      if (hit.valid()) {
        shadow.clear();
        const ShadeState<T> state = shader.prepare(ray, hit, shadow);
        occluded.assign(shadow.size(), 0);
        for (std::size_t k = 0; k < shadow.size(); ++k) {
          ++out.work.rays[1];
          occluded[k] = trace_any(g, regs, shadow[k], shadow_work);
        }
        color = shader.finish(state, occluded.data());
        out.image.z[i] = static_cast<float>(hit.t);
        out.image.object[i] = hit.object;
        out.image.prim[i] = hit.prim;
      }
      out.image.r[i] = static_cast<float>(color.x);
      out.image.g[i] = static_cast<float>(color.y);
      out.image.b[i] = static_cast<float>(color.z);
    }
  }
  return out;
}

template FrameResult render_reference(const Scene&, const SceneGeometry<float>&, int, int, int);
template FrameResult render_reference(const Scene&, const SceneGeometry<double>&, int, int, int);

}  // namespace oprt
