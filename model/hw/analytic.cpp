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
    out.units[u].memory_load_bytes += bytes;
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
  const CameraRays camera(cmd.camera, cmd.width, cmd.height);
  const Shader<T> shader(scene_, setup);
  trace_functional(frame_, geom_, regs, camera, shader, arch_, cmd.width, cmd.height);
  const FunctionalFrame<T>& f = frame_;

  const std::size_t pixels = static_cast<std::size_t>(cmd.width) * cmd.height;
  std::vector<Cycles> last_pop;  // per ray in issue order: when the last FIFO popped it (FIFO room)
  last_pop.reserve(f.ray_count());
  std::vector<Cycles> unit_free(units, 0);
  const bool pipelined = arch_.iu.model == IuModel::pipelined;
  // Each frame's time starts at 0 here, and every unit is idle when a frame starts.
  if (pipelined) pipes_.assign(units, PipelinedUnitTiming(pipeline_config(arch_, Bytes<T>::triangle(arch_.kernel))));
  fifo_peak_.resize(units, 0);
  // Per unit: pop times of rays still queued at the latest push (FIFO occupancy in time).
  std::vector<std::deque<Cycles>> queued(units);
  std::priority_queue<Completion, std::vector<Completion>, std::greater<Completion>> completed;
  std::deque<std::uint32_t> shadow_queue;
  const unsigned depth = static_cast<unsigned>(arch_.fifo_depth);

  // Issue ray `id`: the GPP generates and writes it; every unit takes it in FIFO order.
  auto issue = [&](std::uint32_t id) {
    g += arch_.gpp.cycles_per_ray;
    const std::size_t n = last_pop.size();  // rays issued before this one
    if (depth && n >= depth) g = std::max(g, last_pop[n - depth]);  // room in every FIFO
    // Every later request is at or after g (the GPP's time never decreases, and a unit
    // answers after the ray arrived): grants that ended by then can no longer matter.
    bus.forget_before(g);
    g = transfer(g, Bytes<T>::ray);
    const Cycles avail = g;
    const RayKind kind = f.rays[id].kind;
    ++out.rays[static_cast<int>(kind)];
    const std::uint64_t answer = kind == RayKind::primary ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer;
    Cycles done_all = 0, popped = 0;
    for (std::uint32_t u = 0; u < units; ++u) {
      const UnitRayWork* w = f.find(id, u);
      UnitRun& ur = out.units[u];
      Cycles start, done;
      if (pipelined) {
        PipelinedUnitTiming& p = pipes_[u];
        start = std::max(static_cast<Cycles>(p.ready()), avail);
        const VisitWork* visits = w ? &f.units[u].visits[w->first_visit] : nullptr;
        const auto k = p.take(static_cast<Cycle>(start), static_cast<Cycle>(avail),
                              w ? w->sphere_tests : f.unit_entries[u], visits, w ? w->visits : 0);
        done = transfer(static_cast<Cycles>(k.done), answer);
        p.retire(k.handle, k.done, static_cast<Cycle>(done));
      } else {
        start = std::max(unit_free[u], avail);
        UnitCycles c = f.breakdown(w, u);
        const Cycles end = start + c.busy() + c.stall;
        done = transfer(end, answer);
        c.stall += done - end;
        ur.cycles += c;
        unit_free[u] = done;
      }
      ++ur.rays;
      ++ur.fifo_pushes;
      ++ur.fifo_pops;
      std::deque<Cycles>& q = queued[u];
      while (!q.empty() && q.front() <= avail) q.pop_front();
      fifo_peak_[u] = std::max<std::uint64_t>(fifo_peak_[u], q.size() + 1);
      q.push_back(start);
      done_all = std::max(done_all, done);
      popped = std::max(popped, start);
    }
    last_pop.push_back(popped);
    completed.push({done_all, id});
  };

  std::size_t next_pixel = 0;
  for (;;) {
    if (!completed.empty() && completed.top().at <= g) {
      const std::uint32_t id = completed.top().ray;
      completed.pop();
      const RayRecord<T>& r = f.rays[id];
      if (r.kind == RayKind::primary && f.image.object[r.pixel] != kNone) {
        g += arch_.gpp.cycles_per_hit;
        for (std::uint32_t s = id + 1; s < f.pixel_rays[r.pixel + 1]; ++s) shadow_queue.push_back(s);
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
      issue(f.pixel_rays[next_pixel++]);
      continue;
    }
    if (completed.empty()) break;
    g = completed.top().at;  // the GPP waits for the next answer
  }
  out.makespan = g;
  *cmd.image = f.image;
  for (std::size_t u = 0; u < units; ++u) {
    out.units[u].fifo_peak = fifo_peak_[u];
    if (!pipelined) continue;
    const PipelineStats& p = pipes_[u].stats();
    out.units[u].pipeline = p;
    out.units[u].cycles.sphere = p.stage[0].busy;
    out.units[u].cycles.transform = p.stage[1].busy;
    out.units[u].cycles.primitive = p.stage[2].busy;
    out.units[u].cycles.stall = p.stage[2].memory + p.answer_wait;
  }
  out.per_sphere = f.per_sphere;
  for (std::size_t u = 0; u < units; ++u)
    for (int k = 0; k < kRayKinds; ++k)
      for (std::uint32_t s : assignment_[u]) {
        const WorkCounts& w = f.per_sphere[k][s];
        out.units[u].memory_bytes += w.tri_tests() * Bytes<T>::triangle(arch_.kernel) + w.box_tests * Bytes<T>::node;
      }
  return out;
}

template class AnalyticEngine<float>;
template class AnalyticEngine<double>;

}  // namespace oprt::hw
