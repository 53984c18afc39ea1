// Embree 3 as the yardstick: one frame's rays, primary and shadow, traced by Embree and by
// oprt's reference traversal (--accel bvh, and brute force for scale), on one thread and on
// every core. Not a test: it prints a table (scripts/embree_compare runs it on the paper
// scenes and writes nothing else).
//
// Both tracers see the same rays, built once with oprt's own code as the reference renderer
// builds them (ref/reference.cpp): the camera's primary rays, their nearest hits with the
// BVH geometry, and the shadow rays Shader::prepare issues for those hits (tmax = the light's
// distance). Embree gets two levels: one triangle BLAS per object in the object's local
// coordinates (its mesh rounded to float, at the frame for a deforming object), instanced
// into a top-level scene with the object's local -> world matrix for the frame; an object
// hidden this frame gets no instance. Rays go through rtcIntersect1 and rtcOccluded1 (one
// ray per call, as oprt's traversal takes them; no packets or streams).
//
// oprt is timed with trace_nearest / trace_any over one register file holding every
// sphere, with a visitor that does nothing: the traversal's own work counting still runs
// (it is part of the traversal), the reference renderer's per-sphere accumulation does not.
// Every core: tbb::parallel_for over the rays in a task arena of that many threads (both
// tracers are pure functions of const data). Each figure is the fastest of several runs,
// each tracing the ray list often enough to last --min-run seconds: the machine is shared,
// and the fastest run is the least disturbed. The CPU share column says how disturbed.
//
// Then (--depth N, default 5) the reflection and refraction rays: every pixel's ray tree as
// the reference renderer traces it (ref/frame_trace.h's trace_pixel, one unit holding every
// sphere, Shader at depth N), each secondary ray given to Embree too, their nearest hits
// compared (object, triangle), ties at equal distances counted apart, and both tracers'
// hits on the ray's own parent triangle (self-intersections) counted.
#include "balance/spheres.h"
#include "ref/camera.h"
#include "ref/frame_setup.h"
#include "ref/frame_trace.h"
#include "ref/shading.h"
#include "ref/traverse.h"
#include "base/error.h"
#include "scene/load.h"

#include <CLI/CLI.hpp>
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace oprt {
namespace {

// ------------------------------------------------------------------------------ the rays
struct RaySet {
  std::vector<Ray<float>> primary, shadow;
  std::vector<HitRecord<float>> primary_hit;  // oprt's nearest hits, for the agreement check
};

constexpr auto kIgnoreWork = [](const SphereVisit&) {};

IuRegisters<float> every_sphere(const SceneGeometry<float>& g, const FrameSetup<float>& f) {
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  IuRegisters<float> regs;
  regs.load(f, g, all);
  return regs;
}

RaySet make_rays(const Scene& scene, const SceneGeometry<float>& g, const FrameSetup<float>& f, int width,
                 int height) {
  const CameraRays camera(f.camera, width, height);
  const Shader<float> shader(scene, f);
  const IuRegisters<float> regs = every_sphere(g, f);
  RaySet rs;
  std::vector<SpawnedRay<float>> spawned;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Ray<float> ray = camera.ray<float>(x, y);
      const HitRecord<float> hit = trace_nearest(g, regs, ray, kIgnoreWork);
      rs.primary.push_back(ray);
      rs.primary_hit.push_back(hit);
      if (!hit.valid()) continue;
      spawned.clear();
      shader.shade(ray, hit, 0, false, spawned);
      for (const SpawnedRay<float>& sr : spawned)
        if (sr.kind == RayKind::shadow) rs.shadow.push_back(sr.ray);
    }
  return rs;
}

// The reference's reflection and refraction rays: every pixel's ray tree as the reference
// renderer traces it (trace_pixel over one unit holding every sphere, the shader at the
// given depth), recorded ray by ray: each secondary ray, oprt's nearest hit for it, and the
// hit that spawned it (its parent's object and triangle).
struct SecondarySet {
  std::vector<Ray<float>> rays;
  std::vector<RayKind> kind;
  std::vector<HitRecord<float>> hit;                 // oprt's (the reference's) nearest hit
  std::vector<std::uint32_t> parent_object, parent_prim;
  std::uint64_t tree_rays[kRayKinds] = {};           // every ray of the trees, by kind
};

struct TreeRecorder : RecorderBase {
  SecondarySet* out;
  // The current pixel's rays in trace_pixel's order (ids from 0), and each one's parent:
  // a ray learns its children's ids when it ends, and they begin after it.
  struct Entry {
    Ray<float> ray;
    RayKind kind;
    HitRecord<float> hit;
    std::uint32_t parent;
  };
  std::vector<Entry> pixel;
  std::vector<std::uint32_t> parent_of;
  void begin_ray(const Ray<float>& r, RayKind k, std::size_t, int) {
    if (k == RayKind::primary) pixel.clear(), parent_of.clear();
    const std::size_t id = pixel.size();
    pixel.push_back({r, k, {}, id < parent_of.size() ? parent_of[id] : kNone});
    ++out->tree_rays[static_cast<int>(k)];
  }
  void end_ray(const RayEnd<float>& end) {
    const std::uint32_t i = static_cast<std::uint32_t>(pixel.size() - 1);
    Entry& e = pixel[i];
    e.hit = end.hit;
    if (e.kind == RayKind::reflection || e.kind == RayKind::refraction) {
      const Entry& parent = pixel.at(e.parent);
      out->rays.push_back(e.ray);
      out->kind.push_back(e.kind);
      out->hit.push_back(e.hit);
      out->parent_object.push_back(parent.hit.object);
      out->parent_prim.push_back(parent.hit.prim);
    }
    if (parent_of.size() < i + end.first_child + end.children) parent_of.resize(i + end.first_child + end.children, kNone);
    for (std::uint32_t c = 0; c < end.children; ++c) parent_of[i + end.first_child + c] = i;
  }
};

SecondarySet make_secondary(const Scene& scene, const SceneGeometry<float>& g, const FrameSetup<float>& f, int width,
                            int height, int depth) {
  const CameraRays camera(f.camera, width, height);
  const Shader<float> shader(scene, f, depth);
  const std::vector<IuRegisters<float>> units(1, every_sphere(g, f));
  const FrameTraceInputs<float> in{g, units, camera, shader};
  FrameImage image(width, height);
  PixelScratch<float> scratch;
  SecondarySet set;
  TreeRecorder rec{{}, &set, {}, {}};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) trace_pixel(in, x, y, image, rec, scratch);
  return set;
}

// ------------------------------------------------------------------------------ Embree
class EmbreeScene {
 public:
  EmbreeScene(const Scene& scene, const SceneGeometry<float>& g, const FrameSetup<float>& f, int frame,
              RTCBuildQuality quality, bool robust, const std::string& config)
      : device_(rtcNewDevice(config.c_str())) {
    if (!device_) throw std::runtime_error("rtcNewDevice failed: " + std::to_string(rtcGetDeviceError(nullptr)));
    rtcSetDeviceErrorFunction(
        device_, [](void*, RTCError code, const char* what) { std::fprintf(stderr, "embree error %d: %s\n", code, what); },
        nullptr);
    std::vector<char> visible(scene.objects.size(), 0);
    for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
      if (f.visible[s]) visible[g.object[s]] = 1;
    top_ = rtcNewScene(device_);
    if (robust) rtcSetSceneFlags(top_, RTC_SCENE_FLAG_ROBUST);
    std::vector<Vec3d> moved;
    for (std::uint32_t obj = 0; obj < scene.objects.size(); ++obj) {
      const Object& o = scene.objects[obj];
      const std::vector<Vec3d>* vertices = &o.mesh.vertices;
      if (o.deform) {
        o.deform->at(frame, moved);
        vertices = &moved;
      }
      RTCScene blas = rtcNewScene(device_);
      rtcSetSceneBuildQuality(blas, quality);
      if (robust) rtcSetSceneFlags(blas, RTC_SCENE_FLAG_ROBUST);
      RTCGeometry mesh = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetGeometryBuildQuality(mesh, quality);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), vertices->size()));
      for (std::size_t i = 0; i < vertices->size(); ++i)
        for (int k = 0; k < 3; ++k) v[3 * i + k] = static_cast<float>((*vertices)[i][k]);
      auto* t = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
          mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), o.mesh.triangles.size()));
      for (std::size_t i = 0; i < o.mesh.triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) t[3 * i + k] = o.mesh.triangles[i][k];
      rtcCommitGeometry(mesh);
      rtcAttachGeometryByID(blas, mesh, 0);  // hit.primID is then the mesh's triangle index
      rtcReleaseGeometry(mesh);
      rtcCommitScene(blas);
      blas_.push_back(blas);

      if (!visible[obj]) continue;
      RTCGeometry inst = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(inst, blas);
      float m[12];
      const Affine<double>& w = f.placement[obj].to_world;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m[4 * r + c] = static_cast<float>(w.m[r][c]);
      rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, m);
      rtcCommitGeometry(inst);
      rtcAttachGeometryByID(top_, inst, obj);  // hit.instID[0] is then the object
      rtcReleaseGeometry(inst);
    }
    rtcCommitScene(top_);
  }
  ~EmbreeScene() {
    rtcReleaseScene(top_);
    for (RTCScene s : blas_) rtcReleaseScene(s);
    rtcReleaseDevice(device_);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  HitRecord<float> nearest(const Ray<float>& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    set_ray(rh.ray, r);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(top_, &ctx, &rh);
    HitRecord<float> h;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    h.t = rh.ray.tfar;
    h.object = rh.hit.instID[0];
    h.prim = rh.hit.primID;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
    return h;
  }
  bool occluded(const Ray<float>& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray;
    set_ray(ray, r);
    rtcOccluded1(top_, &ctx, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf on an occluder
  }

 private:
  static void set_ray(RTCRay& e, const Ray<float>& r) {
    e.org_x = r.o.x, e.org_y = r.o.y, e.org_z = r.o.z;
    e.dir_x = r.d.x, e.dir_y = r.d.y, e.dir_z = r.d.z;
    e.tnear = 0;
    e.tfar = r.tmax;
    e.time = 0;
    e.mask = 0xFFFFFFFFu;
    e.id = 0;
    e.flags = 0;
  }

  RTCDevice device_;
  RTCScene top_ = nullptr;
  std::vector<RTCScene> blas_;
};

// ------------------------------------------------------------------------------ timing
// Trace every ray: on this thread (no arena) or with tbb::parallel_for in the arena. Results go to `out` (so nothing is optimised away, and so the runs can
// be compared).
template <typename R, typename F>
void trace_all(const std::vector<Ray<float>>& rays, std::vector<R>& out, tbb::task_arena* arena, F&& trace) {
  out.resize(rays.size());
  if (!arena) {
    for (std::size_t i = 0; i < rays.size(); ++i) out[i] = trace(rays[i]);
    return;
  }
  arena->execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t i = b.begin(); i != b.end(); ++i) out[i] = trace(rays[i]);
    });
  });
}

struct Budget {
  int repeat = 5;          // runs at most
  double seconds = 20;     // stop repeating once the runs so far took this long (at least one run)
  double min_run = 0.25;   // a run traces the ray list as many times as fill this many seconds
};

double cpu_seconds() {  // of the whole process, every thread
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

struct Timing {
  double wall = INFINITY, cpu = 0;  // seconds
};

// Seconds of wall and CPU time per call of f(), from the fastest of the runs. A first call
// warms the caches and sets how many calls make a run: a frame's rays take a few ms on
// Embree, too short to time alone (a thread's wake-up, a timer tick).
template <typename F>
Timing fastest(const Budget& b, F&& f) {
  auto wall = [t0 = std::chrono::steady_clock::now()] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  f();
  const double first = wall();
  const int calls = std::max(1, static_cast<int>(std::ceil(b.min_run / first)));
  Timing best;
  double total = 0;
  for (int i = 0; i < b.repeat && (i == 0 || total < b.seconds); ++i) {
    const double w0 = wall(), c0 = cpu_seconds();
    for (int k = 0; k < calls; ++k) f();
    const double cpu = cpu_seconds() - c0, s = wall() - w0;
    if (s / calls < best.wall) best = {s / calls, cpu / calls};
    total += s;
  }
  return best;
}

struct Row {
  std::string tracer;
  int threads;
  Timing primary, shadow;
  double seconds() const { return primary.wall + shadow.wall; }
  // The share of its threads' wall time the run had on a CPU: about 100 % on an idle
  // machine, less when other jobs took the cores (then the rates are low by as much).
  double cpu_share() const { return (primary.cpu + shadow.cpu) / (seconds() * threads); }
};

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// ------------------------------------------------------------------------------ agreement
struct Agreement {
  std::size_t same = 0, edge = 0, tie = 0, other = 0;
};

// How close a hit lies to an edge of its triangle, in barycentric coordinates.
float edge_distance(const HitRecord<float>& h) { return std::min({h.u, h.v, 1 - h.u - h.v}); }

// Per primary ray: the same (object, triangle), or both missing; else the ray passes within
// 1e-4 (barycentric) of an edge of a triangle either tracer hit, where their rounding differs
// (neither test is exact there: oprt's Moller-Trumbore in float after its own world -> local
// transform, Embree's after its own inverse of the instance matrix, so one may slip through
// a crack the other closes, or take the neighbour across the edge); else the two hits are at
// the same distance (1e-4 relative: a tie broken otherwise); else something else (listed by
// --list).
Agreement compare_primary(const std::vector<HitRecord<float>>& o, const std::vector<HitRecord<float>>& e) {
  Agreement a;
  constexpr float kNear = 1e-4f;
  for (std::size_t i = 0; i < o.size(); ++i) {
    if (o[i].valid() == e[i].valid() && (!o[i].valid() || (o[i].object == e[i].object && o[i].prim == e[i].prim)))
      ++a.same;
    else if ((o[i].valid() && edge_distance(o[i]) < kNear) || (e[i].valid() && edge_distance(e[i]) < kNear))
      ++a.edge;
    else if (o[i].valid() && e[i].valid() && std::fabs(o[i].t - e[i].t) <= kNear * std::max(o[i].t, e[i].t))
      ++a.tie;
    else
      ++a.other;
  }
  return a;
}

// Per reflection or refraction ray: the same (object, triangle), or both missing; else a tie:
// both hit, at distances equal to within the kernels' error, bounded by 64 units in the last
// place of float (2^-24) times |o| + t: either t carries the rounding of the ray's world ->
// local transform (a few ulps of the origin's magnitude) and of its own arithmetic (a few
// ulps of t), in both tracers; 64 is several times the roundings counted. Such a pair is two
// surfaces meeting at the hit (a shared edge, coplanar or coincident faces) where each
// tracer's rounding picks its own. Else a mismatch (`other`; `flag` marks them for --list).
struct SecondaryAgreement {
  std::size_t same = 0, tie = 0, other = 0, other_near_edge = 0;
  std::size_t oprt_self = 0, embree_self = 0;  // nearest hit on the parent's own triangle
};

SecondaryAgreement compare_secondary(const SecondarySet& s, const std::vector<HitRecord<float>>& e,
                                     std::vector<char>& flag) {
  SecondaryAgreement a;
  constexpr double kRoundoff = 1.0 / (1 << 24);
  flag.assign(s.rays.size(), 0);
  for (std::size_t i = 0; i < s.rays.size(); ++i) {
    const HitRecord<float>& o = s.hit[i];
    if (o.valid() && o.object == s.parent_object[i] && o.prim == s.parent_prim[i]) ++a.oprt_self;
    if (e[i].valid() && e[i].object == s.parent_object[i] && e[i].prim == s.parent_prim[i]) ++a.embree_self;
    if (o.valid() == e[i].valid() && (!o.valid() || (o.object == e[i].object && o.prim == e[i].prim))) {
      ++a.same;
      continue;
    }
    if (o.valid() && e[i].valid()) {
      const double t = std::max(o.t, e[i].t);
      const double tol = 64 * kRoundoff * (max_abs_component(Vec3d(s.rays[i].o)) + t);
      if (std::fabs(static_cast<double>(o.t) - e[i].t) <= tol) {
        ++a.tie;
        continue;
      }
    }
    ++a.other;
    flag[i] = 1;
    constexpr float kNear = 1e-4f;
    if ((o.valid() && edge_distance(o) < kNear) || (e[i].valid() && edge_distance(e[i]) < kNear)) ++a.other_near_edge;
  }
  return a;
}

std::size_t count_differences(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
  return n;
}

bool same_hits(const std::vector<HitRecord<float>>& a, const std::vector<HitRecord<float>>& b) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].t != b[i].t || a[i].object != b[i].object || a[i].prim != b[i].prim) return false;
  return true;
}

// The first `count` rays on which the two disagree (primary rays by pixel; width 0: any rays,
// by index and with the ray itself), with what a third opinion finds:
// oprt's watertight kernel in double on the same (float) ray, the closest to exact at hand.
void list_disagreements(const Scene& scene, const std::vector<SphereDef>& spheres, int frame,
                        const std::vector<Ray<float>>& rays, const std::vector<HitRecord<float>>& o,
                        const std::vector<HitRecord<float>>& e, int width, int count,
                        const std::vector<char>* only = nullptr) {
  SceneGeometry<double> g = build_geometry<double>(scene, spheres, Kernel::watertight, Accel::bvh);
  if (has_deforming(scene)) update_deforming(g, scene, frame);
  const FrameSetup<double> f = setup_frame(scene, g, frame);
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  IuRegisters<double> regs;
  regs.load(f, g, all);
  auto show = [](const char* who, std::uint32_t object, std::uint32_t prim, double t, double u, double v) {
    if (object == kNone) return std::printf("    %-28s miss\n", who), void();
    std::printf("    %-28s object %u triangle %u t %.9g u %.3g v %.3g 1-u-v %.3g\n", who, object, prim, t, u, v, 1 - u - v);
  };
  for (std::size_t i = 0; i < o.size() && count > 0; ++i) {
    if (o[i].valid() == e[i].valid() && (!o[i].valid() || (o[i].object == e[i].object && o[i].prim == e[i].prim)))
      continue;
    if (only && !(*only)[i]) continue;
    --count;
    const Ray<double> r{Vec3d(rays[i].o), Vec3d(rays[i].d), kInf<double>};
    const HitRecord<double> w = trace_nearest(g, regs, r, kIgnoreWork);
    if (width > 0) std::printf("  pixel (%zu, %zu):\n", i % width, i / width);
    else std::printf("  ray %zu: origin (%.9g %.9g %.9g) direction (%.9g %.9g %.9g)\n", i, rays[i].o.x, rays[i].o.y,
                     rays[i].o.z, rays[i].d.x, rays[i].d.y, rays[i].d.z);
    show("oprt (Moller, float)", o[i].object, o[i].prim, o[i].t, o[i].u, o[i].v);
    show("Embree", e[i].object, e[i].prim, e[i].t, e[i].u, e[i].v);
    show("oprt (watertight, double)", w.object, w.prim, w.t, w.u, w.v);
  }
}

// ------------------------------------------------------------------------------ main
struct Options {
  std::string scene;
  int frame = 0;
  std::string resolution = "256x256";
  int threads = 0;  // every core
  Budget budget;
  bool brute = true;
  std::string quality = "high";
  std::string embree_config;
  bool robust = false;
  int list = 0;  // disagreeing primary rays to print
  int depth = 5;  // the reflection and refraction rays' depth bound (0: none compared)
};

int run(const Options& o) {
  int width = 0, height = 0;
  char x = 0, extra = 0;
  if (std::sscanf(o.resolution.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width <= 0 ||
      height <= 0)
    throw std::invalid_argument("--resolution: expected WxH, got \"" + o.resolution + "\"");
  const int cores = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
  const RTCBuildQuality quality = o.quality == "high" ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  const std::string load_before = load_average();

  const Scene scene = load_scene(o.scene);
  if (o.frame < 0 || o.frame >= scene.frame_count) throw std::invalid_argument("--frame: out of the scene's range");
  check_motions(scene, o.frame, o.frame);
  const std::vector<SphereDef> spheres = make_spheres(scene, 1);
  SceneGeometry<float> bvh = build_geometry<float>(scene, spheres, Kernel::moller, Accel::bvh);
  if (has_deforming(scene)) update_deforming(bvh, scene, o.frame);
  const FrameSetup<float> fb = setup_frame(scene, bvh, o.frame);
  const IuRegisters<float> rb = every_sphere(bvh, fb);
  const RaySet rays = make_rays(scene, bvh, fb, width, height);
  const EmbreeScene embree(scene, bvh, fb, o.frame, quality, o.robust, o.embree_config);

  std::vector<HitRecord<float>> hits, embree_hits, oprt_hits;
  std::vector<std::uint8_t> occ, embree_occ, oprt_occ;
  std::vector<Row> rows;
  auto measure = [&](const std::string& name, int threads, auto&& nearest, auto&& any) {
    Row r{name, threads, {}, {}};
    std::optional<tbb::task_arena> arena;
    if (threads > 1) arena.emplace(threads);
    tbb::task_arena* a = arena ? &*arena : nullptr;
    r.primary = fastest(o.budget, [&] { trace_all(rays.primary, hits, a, nearest); });
    r.shadow = fastest(o.budget, [&] { trace_all(rays.shadow, occ, a, any); });
    rows.push_back(r);
  };
  auto embree_nearest = [&](const Ray<float>& r) { return embree.nearest(r); };
  auto embree_any = [&](const Ray<float>& r) { return std::uint8_t{embree.occluded(r)}; };
  auto oprt_nearest = [&](const Ray<float>& r) { return trace_nearest(bvh, rb, r, kIgnoreWork); };
  auto oprt_any = [&](const Ray<float>& r) { return std::uint8_t{trace_any(bvh, rb, r, kIgnoreWork)}; };

  const std::string embree_name = "Embree " RTC_VERSION_STRING " rtcIntersect1/rtcOccluded1";
  const std::string bvh_name = "oprt reference --accel bvh";
  measure(embree_name, 1, embree_nearest, embree_any);
  embree_hits = hits, embree_occ = occ;
  measure(bvh_name, 1, oprt_nearest, oprt_any);
  oprt_hits = hits, oprt_occ = occ;
  if (o.brute) {
    SceneGeometry<float> brute = build_geometry<float>(scene, spheres, Kernel::moller, Accel::brute);
    if (has_deforming(scene)) update_deforming(brute, scene, o.frame);
    const FrameSetup<float> fr = setup_frame(scene, brute, o.frame);
    const IuRegisters<float> rr = every_sphere(brute, fr);
    measure(
        "oprt reference --accel brute", 1, [&](const Ray<float>& r) { return trace_nearest(brute, rr, r, kIgnoreWork); },
        [&](const Ray<float>& r) { return std::uint8_t{trace_any(brute, rr, r, kIgnoreWork)}; });
    if (!same_hits(hits, oprt_hits) || count_differences(occ, oprt_occ) != 0)
      throw std::logic_error("oprt brute force and BVH disagree: a bug in the BVH traversal");
  }
  if (cores > 1) {
    measure(embree_name, cores, embree_nearest, embree_any);
    measure(bvh_name, cores, oprt_nearest, oprt_any);
    if (!same_hits(hits, oprt_hits) || count_differences(occ, oprt_occ) != 0)
      throw std::logic_error("oprt on " + std::to_string(cores) + " threads differs from one thread");
  }

  std::size_t hit_count = 0;
  for (const auto& h : rays.primary_hit) hit_count += h.valid();
  if (!same_hits(rays.primary_hit, oprt_hits)) throw std::logic_error("oprt's timed run differs from the ray set's");
  std::size_t triangles = 0;
  for (const Object& obj : scene.objects) triangles += obj.mesh.triangles.size();

  std::printf("%s, frame %d, %dx%d: %zu objects, %zu triangles; %zu primary rays (%zu hit), %zu shadow rays\n",
              o.scene.c_str(), o.frame, width, height, scene.objects.size(), triangles, rays.primary.size(), hit_count,
              rays.shadow.size());
  std::printf("Embree: one BLAS per object (build quality %s%s), one instance per visible object; oprt: %u spheres, "
              "Moller-Trumbore, float\n",
              o.quality.c_str(), o.robust ? ", robust" : "", bvh.sphere_count());
  std::printf("fastest of up to %d runs of >= %.2f s (at most %.0f s of runs per figure); load average before %s, "
              "after %s\n\n",
              o.budget.repeat, o.budget.min_run, o.budget.seconds, load_before.c_str(), load_average().c_str());
  std::printf("| tracer | threads | primary M rays/s | shadow M rays/s | all M rays/s | time / Embree's | CPU share |\n");
  std::printf("|---|--:|--:|--:|--:|--:|--:|\n");
  const double np = static_cast<double>(rays.primary.size()), ns = static_cast<double>(rays.shadow.size());
  for (const Row& r : rows) {
    double embree_s = 0;
    for (const Row& e : rows)
      if (e.tracer == embree_name && e.threads == r.threads) embree_s = e.seconds();
    std::printf("| %s | %d | %.2f | %.2f | %.2f | %.2fx | %.0f %% |\n", r.tracer.c_str(), r.threads,
                np / r.primary.wall / 1e6, ns / r.shadow.wall / 1e6, (np + ns) / r.seconds() / 1e6, r.seconds() / embree_s,
                100 * r.cpu_share());
  }

  // What oprt's BVH traversal does per ray (the work the IUs are charged for): primary and
  // shadow (the secondary rays follow below).
  for (int k = 0; k < 2; ++k) {
    const bool primary = k == static_cast<int>(RayKind::primary);
    const std::vector<Ray<float>>& list = primary ? rays.primary : rays.shadow;
    WorkCounts w;
    auto add = [&w](const SphereVisit& v) { w += v.work; };
    for (const Ray<float>& r : list) primary ? void(trace_nearest(bvh, rb, r, add)) : void(trace_any(bvh, rb, r, add));
    const double n = static_cast<double>(list.size());
    std::printf("%soprt --accel bvh per %s ray: %.1f sphere tests, %.2f transforms, %.1f box tests, %.1f triangle tests\n",
                primary ? "\n" : "", primary ? "primary" : "shadow", w.sphere_tests / n, w.transforms / n,
                w.box_tests / n, w.tri_tests() / n);
  }
  const Agreement a = compare_primary(oprt_hits, embree_hits);
  std::printf("agreement, primary rays: %zu of %zu the same (object, triangle) or both missing; differing: %zu "
              "within 1e-4 of a triangle's edge, %zu at the same distance, %zu otherwise\n",
              a.same, rays.primary.size(), a.edge, a.tie, a.other);
  std::printf("agreement, shadow rays: %zu of %zu answered differently (occluded or not)\n",
              count_differences(oprt_occ, embree_occ), rays.shadow.size());
  if (o.list > 0) list_disagreements(scene, spheres, o.frame, rays.primary, oprt_hits, embree_hits, width, o.list);
  if (o.depth > 0) {
    // The reference's reflection and refraction rays, each traced by Embree as well.
    const SecondarySet sec = make_secondary(scene, bvh, fb, width, height, o.depth);
    std::vector<HitRecord<float>> sec_embree;
    trace_all(sec.rays, sec_embree, nullptr, embree_nearest);
    std::vector<HitRecord<float>> sec_oprt;
    trace_all(sec.rays, sec_oprt, nullptr, oprt_nearest);
    if (!same_hits(sec_oprt, sec.hit)) throw std::logic_error("oprt's secondary hits differ from the ray trees'");
    std::vector<char> flag;
    const SecondaryAgreement s = compare_secondary(sec, sec_embree, flag);
    std::size_t refl = 0;
    for (RayKind k : sec.kind) refl += k == RayKind::reflection;
    const double n = static_cast<double>(sec.rays.size());
    std::printf("\nsecondary rays, depth %d: the reference's trees hold %llu primary, %llu shadow, %llu reflection, %llu "
                "refraction rays\n",
                o.depth, (unsigned long long)sec.tree_rays[0], (unsigned long long)sec.tree_rays[1],
                (unsigned long long)sec.tree_rays[2], (unsigned long long)sec.tree_rays[3]);
    std::printf("agreement, reflection and refraction rays: %zu of %zu (%zu reflection, %zu refraction) the same "
                "(object, triangle) or both missing; differing: %zu ties (equal t within the kernels' error, %.4f %%), "
                "%zu otherwise (%zu of them within 1e-4 of a triangle's edge)\n",
                s.same, sec.rays.size(), refl, sec.rays.size() - refl, s.tie, n > 0 ? 100.0 * s.tie / n : 0.0, s.other,
                s.other_near_edge);
    std::printf("self-intersections (nearest hit on the parent's own triangle): oprt %zu, Embree %zu\n", s.oprt_self,
                s.embree_self);
    if (sec.rays.empty()) return 0;  // nothing reflects or transmits: nothing to time
    const Timing te = fastest(o.budget, [&] { trace_all(sec.rays, sec_embree, nullptr, embree_nearest); });
    const Timing to = fastest(o.budget, [&] { trace_all(sec.rays, sec_oprt, nullptr, oprt_nearest); });
    std::printf("secondary rays on 1 thread: Embree %.2f M rays/s, oprt --accel bvh %.2f M rays/s (%.2fx Embree's time)\n",
                n / te.wall / 1e6, n / to.wall / 1e6, to.wall / te.wall);
    if (o.list > 0 && s.other > 0)
      list_disagreements(scene, spheres, o.frame, sec.rays, sec.hit, sec_embree, 0, o.list, &flag);
  }
  return 0;
}

}  // namespace
}  // namespace oprt

int main(int argc, char** argv) {
  oprt::Options o;
  CLI::App app{"Trace one frame's rays with Embree 3 and with oprt's reference traversal; print rays/s"};
  app.add_option("SCENE", o.scene, "scene file (.json, .aff, .gltf)")->required();
  app.add_option("--frame", o.frame, "frame whose rays are traced")->capture_default_str();
  app.add_option("--resolution", o.resolution, "WxH")->capture_default_str();
  app.add_option("--threads", o.threads, "threads of the every-core rows (0: every core)")->capture_default_str();
  app.add_option("--repeat", o.budget.repeat, "runs per figure, the fastest reported")->capture_default_str();
  app.add_option("--budget", o.budget.seconds, "stop repeating a figure after this many seconds")->capture_default_str();
  app.add_option("--min-run", o.budget.min_run, "seconds of one run (the ray list traced as often as needed)")
      ->capture_default_str();
  app.add_flag("!--no-brute", o.brute, "skip oprt's brute-force row (slow on large scenes)");
  app.add_option("--embree-quality", o.quality, "Embree BLAS build quality")
      ->check(CLI::IsMember({"high", "medium"}))
      ->capture_default_str();
  app.add_flag("--embree-robust", o.robust, "RTC_SCENE_FLAG_ROBUST: Embree's watertight mode (slower)");
  app.add_option("--embree-config", o.embree_config, "rtcNewDevice's configuration (e.g. verbose=1 prints its ISA)");
  app.add_option("--list", o.list, "print up to N primary rays (and N secondary rays) on which the two disagree")
      ->capture_default_str();
  app.add_option("--depth", o.depth, "compare the reference's reflection and refraction rays to this depth (0: none)")
      ->check(CLI::Range(0, oprt::kMaxDepth))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    return oprt::run(o);
  } catch (const oprt::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "embree_compare: %s\n", e.what());
    return 2;
  }
}
