// The functional work of one pixel, as the engine does it: the primary ray goes to every
// unit (trace_nearest over each unit's registers), the GPP keeps the nearest of their
// answers and shades it, each shadow ray goes to every unit (trace_any), and the pixel's
// colour follows. Nothing here depends on time, so a frame's pixels can be traced in any
// order and on any number of threads, ahead of the timed model that then times this work
// (gem5's atomic/timing split). The reference renderer is the case of one unit holding
// every sphere.
//
// The recorder sees, in order, for each ray: begin_ray(ray, kind, pixel, slot), then per
// unit the ray goes to begin_unit(u), visit(SphereVisit) per sphere tested, end_unit(u,
// answer), wave_end() after the last unit of each wave (ref/route.h), skip(u) for a unit
// that `ordered` routing spared; then end_ray(). It owns what is kept (work tables, the
// units' answers for the timed model). Broadcast: every unit, one wave.
#pragma once

#include "ref/camera.h"
#include "ref/image.h"
#include "ref/route.h"
#include "ref/shading.h"

#include <vector>

namespace oprt {

// One unit's answer to a ray: the nearest hit (primary) or whether it is occluded (shadow).
template <typename T>
struct UnitAnswer {
  HitRecord<T> hit;
  bool occluded = false;
};

// What a frame's pixels share: read-only, safe to use from many threads at once.
template <typename T>
struct FrameTraceInputs {
  const SceneGeometry<T>& geometry;
  const std::vector<IuRegisters<T>>& units;
  const CameraRays& camera;
  const Shader<T>& shader;
  bool log_stages = false;  // the memory model needs each visit's exit stages in memory order
  const RouteTable<T>* route = nullptr;  // null or broadcast: every unit
};

// Per-thread scratch, reused from pixel to pixel.
template <typename T>
struct PixelScratch {
  std::vector<Ray<T>> shadow;
  std::vector<std::uint8_t> occluded;
  StageLog log;
  std::vector<typename RouteTable<T>::Entered> entered;
};

// The units ray `ray` goes to, in waves (ref/route.h): unit(u) for each, which returns true
// once a shadow ray is occluded; `limit()` the closest hit so far (ordered routing skips a
// unit entered beyond it).
template <typename T, typename Recorder, typename Unit, typename Limit>
void route_ray(const FrameTraceInputs<T>& in, const Ray<T>& ray, std::uint32_t key, Recorder& rec,
               PixelScratch<T>& scratch, Unit&& unit, Limit&& limit) {
  const RouteTable<T>* r = in.route;
  if (!r || !r->routed()) {
    for (std::uint32_t u = 0; u < in.units.size(); ++u) unit(u);
    rec.wave_end();
    return;
  }
  const std::size_t n = r->entered(ray, scratch.entered, key);
  if (r->route == Route::multicast) {
    for (std::size_t i = 0; i < n; ++i) unit(scratch.entered[i].unit);
    rec.wave_end();
    return;
  }
  std::size_t i = 0;
  bool done = false;
  while (i < n && !done) {
    const T l = limit();  // the closest hit after the waves so far
    std::uint32_t in_wave = 0;
    for (; i < n && in_wave < r->wave; ++i) {
      const std::uint32_t u = scratch.entered[i].unit;
      if (!r->worth(ray, u, l, key)) {
        rec.skip(u);
        continue;
      }
      done = unit(u) || done;
      ++in_wave;
    }
    if (in_wave) rec.wave_end();
  }
  for (; i < n; ++i) rec.skip(scratch.entered[i].unit);  // after a shadow ray's occluder
}

template <typename T, typename Recorder>
void trace_pixel(const FrameTraceInputs<T>& in, int x, int y, FrameImage& image, Recorder& rec,
                 PixelScratch<T>& scratch) {
  const std::size_t pixel = static_cast<std::size_t>(y) * image.width + x;
  StageLog* log = in.log_stages ? &scratch.log : nullptr;
  auto visit = [&rec](const SphereVisit& v) { rec.visit(v); };
  const Ray<T> ray = in.camera.template ray<T>(x, y);
  const std::uint32_t key = share_key(x, y);  // which copy of a replicated sphere takes the pixel's rays
  rec.begin_ray(ray, RayKind::primary, pixel, 0);
  HitRecord<T> best;
  route_ray(
      in, ray, key, rec, scratch,
      [&](std::uint32_t u) {
        rec.begin_unit(u);
        UnitAnswer<T> a;
        a.hit = trace_nearest(in.geometry, in.units[u], ray, visit, log, key);
        rec.end_unit(u, a);
        if (a.hit.valid() && closer(a.hit, best)) best = a.hit;
        return false;
      },
      [&] { return best.valid() ? best.t : ray.tmax; });
  rec.end_ray();
  Vec3d colour = in.shader.background();
  if (best.valid()) {
    scratch.shadow.clear();
    const ShadeState<T> state = in.shader.prepare(ray, best, scratch.shadow);
    scratch.occluded.assign(scratch.shadow.size(), 0);
    for (std::uint32_t k = 0; k < scratch.shadow.size(); ++k) {
      const Ray<T>& shadow = scratch.shadow[k];
      rec.begin_ray(shadow, RayKind::shadow, pixel, k);
      bool occluded = false;
      route_ray(
          in, shadow, key, rec, scratch,
          [&](std::uint32_t u) {
            rec.begin_unit(u);
            UnitAnswer<T> a;
            a.occluded = trace_any(in.geometry, in.units[u], shadow, visit, log, key);
            rec.end_unit(u, a);
            occluded = occluded || a.occluded;
            return occluded;
          },
          [&] { return shadow.tmax; });
      rec.end_ray();
      scratch.occluded[k] = occluded ? 1 : 0;
    }
    colour = in.shader.finish(state, scratch.occluded.data());
    image.z[pixel] = static_cast<float>(best.t);
    image.object[pixel] = best.object;
    image.prim[pixel] = best.prim;
  }
  image.r[pixel] = static_cast<float>(colour.x);
  image.g[pixel] = static_cast<float>(colour.y);
  image.b[pixel] = static_cast<float>(colour.z);
}

// Pixels per chunk of parallel work: a fixed number (never derived from the thread count),
// so that chunk outputs, and everything assembled from them, are the same for any count.
constexpr std::size_t kPixelsPerChunk = 512;

}  // namespace oprt
