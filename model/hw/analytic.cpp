#include "hw/analytic.h"

#include "ref/camera.h"
#include "ref/shading.h"

#include <algorithm>
#include <deque>
#include <queue>

namespace oprt::hw {

namespace {
using Cycles = std::uint64_t;

struct Completion {
  Cycles at;
  std::uint32_t ray;
  bool operator>(const Completion& o) const { return at != o.at ? at > o.at : ray > o.ray; }
};
}  // namespace

template <typename T>
FrameRun AnalyticEngine<T>::run_frame(const FrameCommand& cmd) {
  const std::size_t units = assignment_.size();
  FrameRun out;
  out.units.resize(units);
  for (UnitRun& u : out.units)
    for (auto& w : u.per_sphere) w.assign(geom_.sphere_count(), WorkCounts{});

  const bool shared = arch_.bus.model == BusModel::shared;
  Calendar<Cycles> bus;
  auto transfer = [&](Cycles at, std::uint64_t bytes) -> Cycles {  // returns when it is done
    ++out.bus_transfers;
    out.bus_bytes += bytes;
    if (!shared) return at;
    const Cycles occupancy = arch_.bus.arbitration_cycles + (bytes + arch_.bus.bytes_per_cycle - 1) / arch_.bus.bytes_per_cycle;
    out.bus_busy += occupancy;
    return bus.reserve(at, occupancy);
  };

  Cycles g = 0;  // the GPP's time
  // Geometry moved by an assignment change, and deforming geometry, is written into object
  // memory inside the frame (as Gpp::load_memories does); setup() loaded the rest.
  loaded_.resize(units);
  for (std::size_t u = 0; u < units; ++u) {
    std::uint64_t bytes = 0;
    for (std::uint32_t s : assignment_[u])
      if (geom_.deforming[s] || std::find(loaded_[u].begin(), loaded_[u].end(), s) == loaded_[u].end())
        bytes += geom_.memory_bytes(s);
    if (loaded_[u] == assignment_[u] && bytes == 0) continue;
    out.memory_load_bytes += bytes;
    const Cycles before = g;
    g = transfer(g, bytes);
    out.memory_load_cycles += g - before;
    loaded_[u] = assignment_[u];
  }

  const FrameSetup<T> setup = setup_frame(scene_, geom_, cmd.frame, cmd.to_world, cmd.camera);
  std::vector<IuRegisters<T>> regs(units);
  for (std::size_t u = 0; u < units; ++u) {
    regs[u].load(setup, geom_, assignment_[u]);
    g = transfer(g, assignment_[u].size() * Bytes<T>::sphere_config);
  }

  const std::size_t pixels = static_cast<std::size_t>(cmd.width) * cmd.height;
  struct InFlight {  // a ray and the answers merged so far
    RayRecord<T> rec;
    HitRecord<T> hit;
    bool occluded = false;
  };
  std::vector<InFlight> rays;
  rays.reserve(pixels * (1 + scene_.lights.size()));
  std::vector<Cycles> last_pop;  // per ray: when the last FIFO popped it (FIFO room)
  std::vector<Cycles> unit_free(units, 0);
  struct Pixel {
    ShadeState<T> shade;
    std::uint32_t shadow_left = 0;
    std::vector<std::uint8_t> occluded;
  };
  std::vector<Pixel> px(pixels);
  std::priority_queue<Completion, std::vector<Completion>, std::greater<Completion>> completed;
  std::deque<std::uint32_t> shadow_queue;
  StageLog log;
  StageLog* logp = arch_.memory.model == MemoryModel::latency ? &log : nullptr;
  const unsigned depth = static_cast<unsigned>(arch_.fifo_depth);

  // Issue ray `id`: the GPP generates and writes it; every unit takes it in FIFO order.
  auto issue = [&](std::uint32_t id) {
    g += arch_.gpp.cycles_per_ray;
    if (depth && id >= depth) g = std::max(g, last_pop[id - depth]);  // room in every FIFO
    // Every later request is at or after g (the GPP's time never decreases, and a unit
    // answers after the ray arrived): grants that ended by then can no longer matter.
    bus.forget_before(g);
    g = transfer(g, Bytes<T>::ray);
    const Cycles avail = g;
    InFlight& r = rays[id];
    const int kind = static_cast<int>(r.rec.kind);
    ++out.rays[kind];
    Cycles done_all = 0, popped = 0;
    for (std::size_t u = 0; u < units; ++u) {
      UnitRun& ur = out.units[u];
      const Cycles start = std::max(unit_free[u], avail);
      UnitCycles c;
      auto visit = [&](const SphereVisit& v) { c += charge_visit<T>(v, arch_, ur.per_sphere[kind], ur.memory_bytes); };
      if (r.rec.kind == RayKind::primary) {
        const HitRecord<T> h = trace_nearest(geom_, regs[u], r.rec.ray, visit, logp);
        if (h.valid() && closer(h, r.hit)) r.hit = h;
      } else {
        r.occluded = trace_any(geom_, regs[u], r.rec.ray, visit, logp) || r.occluded;
      }
      const Cycles end = start + c.busy() + c.stall;
      const Cycles done = transfer(end, r.rec.kind == RayKind::primary ? Bytes<T>::nearest_answer
                                                                         : Bytes<T>::shadow_answer);
      c.stall += done - end;
      ur.cycles += c;
      ++ur.rays;
      unit_free[u] = done;
      done_all = std::max(done_all, done);
      popped = std::max(popped, start);
    }
    last_pop.push_back(popped);
    completed.push({done_all, id});
  };
  auto new_ray = [&](const Ray<T>& ray, RayKind kind, std::uint32_t pixel, std::uint32_t slot) {
    rays.push_back({{ray, kind, pixel, slot}, {}, false});
    return static_cast<std::uint32_t>(rays.size() - 1);
  };

  FrameImage& img = *cmd.image;
  auto finish = [&](std::uint32_t pixel, const Vec3d& c) {
    img.r[pixel] = static_cast<float>(c.x);
    img.g[pixel] = static_cast<float>(c.y);
    img.b[pixel] = static_cast<float>(c.z);
  };
  const CameraRays camera(cmd.camera, cmd.width, cmd.height);
  const Shader<T> shader(scene_, setup);
  std::vector<Ray<T>> shadow;
  std::size_t next_pixel = 0;
  for (;;) {
    if (!completed.empty() && completed.top().at <= g) {
      const std::uint32_t id = completed.top().ray;
      completed.pop();
      const InFlight& r = rays[id];
      const std::uint32_t p = r.rec.pixel;
      if (r.rec.kind == RayKind::primary) {
        if (!r.hit.valid()) {
          finish(p, shader.background());
          continue;
        }
        g += arch_.gpp.cycles_per_hit;
        shadow.clear();
        px[p].shade = shader.prepare(r.rec.ray, r.hit, shadow);
        img.z[p] = static_cast<float>(r.hit.t);
        img.object[p] = r.hit.object;
        img.prim[p] = r.hit.prim;
        px[p].shadow_left = static_cast<std::uint32_t>(shadow.size());
        px[p].occluded.assign(shadow.size(), 0);
        for (std::uint32_t k = 0; k < shadow.size(); ++k)
          shadow_queue.push_back(new_ray(shadow[k], RayKind::shadow, p, k));
        if (shadow.empty()) finish(p, shader.finish(px[p].shade, nullptr));
      } else {
        px[p].occluded[r.rec.slot] = r.occluded ? 1 : 0;
        if (--px[p].shadow_left == 0) finish(p, shader.finish(px[p].shade, px[p].occluded.data()));
      }
      continue;
    }
    if (!shadow_queue.empty()) {
      const std::uint32_t id = shadow_queue.front();
      shadow_queue.pop_front();
      issue(id);
      continue;
    }
    if (next_pixel < pixels) {
      const int x = static_cast<int>(next_pixel % cmd.width), y = static_cast<int>(next_pixel / cmd.width);
      issue(new_ray(camera.ray<T>(x, y), RayKind::primary, static_cast<std::uint32_t>(next_pixel), 0));
      ++next_pixel;
      continue;
    }
    if (completed.empty()) break;
    g = completed.top().at;  // the GPP waits for the next answer
  }
  out.makespan = g;
  return out;
}

template class AnalyticEngine<float>;
template class AnalyticEngine<double>;

}  // namespace oprt::hw
