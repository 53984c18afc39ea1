// The functional work of one pixel, as the engine does it: the primary ray goes to every
// unit (trace_nearest over each unit's registers), the GPP keeps the nearest of their
// answers and shades it (ref/shading.h), which spawns a shadow ray per light and, where the
// material reflects or transmits, a reflection and a refraction ray; each shadow ray goes to
// every unit (trace_any), each secondary ray as the primary ray did, its hit shaded in turn,
// to the scene's depth; the pixel's colour follows from the answers. A pixel's rays are
// traced breadth first, in the order they are spawned: a ray's id comes after its parent's,
// and the rays one hit spawns are consecutive. Nothing here depends on time, so a frame's pixels can be traced in any
// order and on any number of threads, ahead of the timed model that then times this work
// (gem5's atomic/timing split). The reference renderer is the case of one unit holding
// every sphere.
//
// The recorder sees, in order, for each ray: begin_ray(ray, kind, pixel, depth), then per
// unit the ray goes to begin_unit(u), visit(SphereVisit) per sphere tested, end_unit(u,
// answer), wave_end() after the last unit of each wave (ref/route.h), skip(u) for a unit
// that `ordered` routing spared; then end_ray(RayEnd). It owns what is kept (work tables, the
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

// Every callback of a recorder, doing nothing: a recorder derives from it and writes only
// the ones it keeps something from.
struct RecorderBase {
  template <typename Ray>
  void begin_ray(const Ray&, RayKind, std::size_t, int) {}
  void begin_unit(std::uint32_t) {}
  void visit(const SphereVisit&) {}
  template <typename Answer>
  void end_unit(std::uint32_t, const Answer&) {}
  void wave_end() {}
  void skip(std::uint32_t) {}
  template <typename End>
  void end_ray(const End&) {}
};

// What the recorder learns when a ray is done: a nearest-hit ray's hit (invalid for a miss
// and for shadow rays), and the rays that hit spawned, at ids [id + first_child, id +
// first_child + children) (first_child 0: none).
template <typename T>
struct RayEnd {
  HitRecord<T> hit;
  std::uint32_t first_child = 0, children = 0;
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

// One ray of a pixel's tree (trace_pixel), with what its answer adds up to.
template <typename T>
struct PixelRay {
  SpawnedRay<T> spawned;  // the ray, its kind, its weight in its parent's colour, its medium
  std::uint8_t depth = 0;
  bool answer = false;    // shadow: occluded; else: it hit
  std::uint32_t first_child = 0, children = 0;  // indices in the pixel's rays
  Vec3d colour{0};        // a nearest-hit ray's colour, once its children have theirs
};

// Per-thread scratch, reused from pixel to pixel.
template <typename T>
struct PixelScratch {
  std::vector<PixelRay<T>> rays;
  std::vector<SpawnedRay<T>> spawned;
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

// Ray `ray` through the units the route chooses: the nearest of their hits.
template <typename T, typename Recorder>
HitRecord<T> trace_nearest_ray(const FrameTraceInputs<T>& in, const Ray<T>& ray, std::uint32_t key, Recorder& rec,
                               PixelScratch<T>& scratch) {
  StageLog* log = in.log_stages ? &scratch.log : nullptr;
  auto visit = [&rec](const SphereVisit& v) { rec.visit(v); };
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
  return best;
}

// ... and a shadow ray: whether any unit found it occluded.
template <typename T, typename Recorder>
bool trace_shadow_ray(const FrameTraceInputs<T>& in, const Ray<T>& shadow, std::uint32_t key, Recorder& rec,
                      PixelScratch<T>& scratch) {
  StageLog* log = in.log_stages ? &scratch.log : nullptr;
  auto visit = [&rec](const SphereVisit& v) { rec.visit(v); };
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
  return occluded;
}

// A nearest-hit ray's colour from its own and its children's (traced after it): a shadow
// ray adds its light's term unless occluded, a secondary ray its weight times its colour.
template <typename T>
Vec3d gather_colour(const std::vector<PixelRay<T>>& rays, const PixelRay<T>& r) {
  Vec3d c = r.colour;
  for (std::uint32_t k = r.first_child; k < r.first_child + r.children; ++k) {
    const PixelRay<T>& child = rays[k];
    if (child.spawned.kind == RayKind::shadow) {
      if (!child.answer) c += child.spawned.weight;
    } else {
      c += child.spawned.weight * child.colour;
    }
  }
  return c;
}

template <typename T, typename Recorder>
void trace_pixel(const FrameTraceInputs<T>& in, int x, int y, FrameImage& image, Recorder& rec,
                 PixelScratch<T>& scratch) {
  const std::size_t pixel = static_cast<std::size_t>(y) * image.width + x;
  const std::uint32_t key = share_key(x, y);  // which copy of a replicated sphere takes the pixel's rays
  auto& rays = scratch.rays;
  rays.clear();
  rays.emplace_back();
  rays[0].spawned.ray = in.camera.template ray<T>(x, y);
  rays[0].spawned.kind = RayKind::primary;
  HitRecord<T> primary_hit;
  for (std::uint32_t i = 0; i < rays.size(); ++i) {
    const SpawnedRay<T> ray = rays[i].spawned;  // a copy: spawning grows `rays`
    const int depth = rays[i].depth;
    rec.begin_ray(ray.ray, ray.kind, pixel, depth);
    RayEnd<T> end;
    if (ray.kind == RayKind::shadow) {
      rays[i].answer = trace_shadow_ray(in, ray.ray, key, rec, scratch);
    } else {
      end.hit = trace_nearest_ray(in, ray.ray, key, rec, scratch);
      if (i == 0) primary_hit = end.hit;
      rays[i].answer = end.hit.valid();
      rays[i].colour = in.shader.background();
      if (end.hit.valid()) {
        scratch.spawned.clear();
        rays[i].colour = in.shader.shade(ray.ray, end.hit, depth, ray.inside, scratch.spawned);
        rays[i].first_child = static_cast<std::uint32_t>(rays.size());
        rays[i].children = static_cast<std::uint32_t>(scratch.spawned.size());
        for (const SpawnedRay<T>& s : scratch.spawned) {
          rays.emplace_back();
          rays.back().spawned = s;
          rays.back().depth = static_cast<std::uint8_t>(depth + (s.kind == RayKind::shadow ? 0 : 1));
        }
        if (rays[i].children) end.first_child = rays[i].first_child - i, end.children = rays[i].children;
      }
    }
    rec.end_ray(end);
  }
  for (std::size_t i = rays.size(); i-- > 0;)  // children after their parents: colours bottom up
    if (rays[i].spawned.kind != RayKind::shadow && rays[i].answer) rays[i].colour = gather_colour(rays, rays[i]);
  const Vec3d colour = rays[0].colour;
  if (primary_hit.valid()) {
    image.z[pixel] = static_cast<float>(primary_hit.t);
    image.object[pixel] = primary_hit.object;
    image.prim[pixel] = primary_hit.prim;
  }
  image.r[pixel] = static_cast<float>(colour.x);
  image.g[pixel] = static_cast<float>(colour.y);
  image.b[pixel] = static_cast<float>(colour.z);
}

// Pixels per chunk of parallel work: a fixed number (never derived from the thread count),
// so that chunk outputs, and everything assembled from them, are the same for any count.
constexpr std::size_t kPixelsPerChunk = 512;

}  // namespace oprt
