#include "ref/reference.h"

#include "ref/frame_trace.h"
#include "ref/parallel.h"
#include "ref/stop.h"

#include <numeric>

#include <oneapi/tbb/enumerable_thread_specific.h>

namespace oprt {

WorkCounts FrameWork::total(RayKind k) const {
  WorkCounts w;
  for (const WorkCounts& s : per_sphere[static_cast<int>(k)]) w += s;
  return w;
}

WorkCounts FrameWork::total() const {
  WorkCounts w;
  for (int k = 0; k < kRayKinds; ++k) w += total(static_cast<RayKind>(k));
  return w;
}

FrameWork& FrameWork::operator+=(const FrameWork& o) {
  for (int k = 0; k < kRayKinds; ++k) {
    rays[k] += o.rays[k];
    if (o.by_depth.size() > by_depth.size()) by_depth.resize(o.by_depth.size(), {});
    for (std::size_t d = 0; d < o.by_depth.size(); ++d) by_depth[d][k] += o.by_depth[d][k];
    for (std::size_t s = 0; s < per_sphere[k].size(); ++s) per_sphere[k][s] += o.per_sphere[k][s];
  }
  return *this;
}

namespace {
// The reference keeps only the work per sphere and ray kind.
struct WorkRecorder : RecorderBase {
  FrameWork* work;
  int kind = 0;
  template <typename Ray>
  void begin_ray(const Ray&, RayKind k, std::size_t, int depth) {
    kind = static_cast<int>(k);
    ++work->rays[kind];
    const auto d = static_cast<std::size_t>(depth);
    if (d >= work->by_depth.size()) work->by_depth.resize(d + 1, {});
    ++work->by_depth[d][kind];
  }
  void visit(const SphereVisit& v) {
    if (v.sphere != kNone) work->per_sphere[kind][v.sphere] += v.work;
  }
};
}  // namespace

template <typename T>
FrameResult render_reference(const Scene& scene, const SceneGeometry<T>& g, int frame, int width, int height,
                             int depth) {
  const FrameSetup<T> f = setup_frame(scene, g, frame);
  const CameraRays camera(f.camera, width, height);
  const Shader<T> shader(scene, f, depth);
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  std::vector<IuRegisters<T>> one_unit(1);
  one_unit[0].load(f, g, all);
  const FrameTraceInputs<T> in{g, one_unit, camera, shader};

  FrameResult out{FrameImage(width, height), FrameWork(g.sphere_count())};
  struct Local {
    FrameWork work;
    PixelScratch<T> scratch;
  };
  tbb::enumerable_thread_specific<Local> locals([&] { return Local{FrameWork(g.sphere_count()), {}}; });
  parallel_chunks(out.image.size(), kPixelsPerChunk, [&](std::size_t, std::size_t begin, std::size_t end) {
    throw_if_stopped();
    Local& l = locals.local();
    WorkRecorder rec{{}, &l.work};
    for (std::size_t p = begin; p < end; ++p)
      trace_pixel(in, static_cast<int>(p % width), static_cast<int>(p / width), out.image, rec, l.scratch);
  });
  for (const Local& l : locals) out.work += l.work;  // integer sums: the same in any order
  return out;
}

template FrameResult render_reference(const Scene&, const SceneGeometry<float>&, int, int, int, int);
template FrameResult render_reference(const Scene&, const SceneGeometry<double>&, int, int, int, int);

}  // namespace oprt
