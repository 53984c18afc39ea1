#include "timing/analytic.h"

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

// Unit u's object memory becomes a cache, empty (ObjectMemory::load_transport).
template <typename T>
void AnalyticEngine<T>::cold_cache(std::size_t u) {
  const auto& c = arch_.memory.cache;
  caches_[u] = Cache(arch_.memory.sram_bytes, static_cast<std::uint32_t>(c.line_bytes), static_cast<std::uint32_t>(c.ways),
                     c.replacement, u + 1);
  windows_[u] = MissWindow(static_cast<std::uint32_t>(c.misses_outstanding));
}

template <typename T>
void AnalyticEngine<T>::setup() {
  loaded_ = assignment_;
  cached_.assign(assignment_.size(), 0);
  caches_.resize(assignment_.size());
  windows_.resize(assignment_.size());
  for (std::size_t u = 0; u < assignment_.size(); ++u)
    if (memory_is_cache(arch_, assigned_bytes(geom_, assignment_[u]))) {
      cold_cache(u);
      cached_[u] = 1;
    }
}

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
  // memory inside the frame (as Gpp::load_memories does, caches included); setup() loaded
  // the rest.
  loaded_.resize(units);
  cached_.resize(units, 0);
  caches_.resize(units);
  windows_.resize(units);
  const GeometryAddresses<T> at(geom_);
  std::vector<std::pair<std::uint64_t, std::uint64_t>> rewritten;
  for (std::uint32_t s = 0; s < geom_.sphere_count(); ++s)
    if (geom_.deforming[s] && arch_.memory.sram_bytes) {
      rewritten.push_back(at.triangles_of(geom_, s));
      rewritten.push_back(at.nodes_of(geom_, s));
    }
  const auto& cc = arch_.memory.cache;
  for (std::size_t u = 0; u < units; ++u) {
    out.units[u].assigned_bytes = assigned_bytes(geom_, assignment_[u]);
    const bool cache = memory_is_cache(arch_, out.units[u].assigned_bytes);
    out.units[u].cache = cache;
    std::uint64_t bytes = 0;
    for (std::uint32_t s : assignment_[u])
      if (geom_.deforming[s] ||
          (!cache && (cached_[u] || std::find(loaded_[u].begin(), loaded_[u].end(), s) == loaded_[u].end())))
        bytes += geom_.memory_bytes(s);
    if (loaded_[u] == assignment_[u] && cache == static_cast<bool>(cached_[u]) && bytes == 0) continue;
    if (cache && !cached_[u]) cold_cache(u);
    if (cache)
      for (const auto& [first, end] : rewritten)
        caches_[u].invalidate(first / cc.line_bytes, (end + cc.line_bytes - 1) / cc.line_bytes);
    cached_[u] = cache ? 1 : 0;
    out.memory_load_bytes += bytes;
    out.units[u].memory_load_bytes += bytes;
    const Cycles before = g;
    g = transfer(g, bytes);
    out.memory_load_cycles += g - before;
    loaded_[u] = assignment_[u];
  }
  // This frame's time starts at 0: every fill of the last has arrived.
  for (std::size_t u = 0; u < units; ++u)
    if (cached_[u]) {
      caches_[u].settle();
      windows_[u].clear();
    }
  // DRAM channels (dram.h): units_per_channel units each, one line at a time.
  const std::uint32_t per_channel = static_cast<std::uint32_t>(arch_.memory.dram.units_per_channel);
  std::vector<Calendar<Cycles>> channels(units / per_channel + 1);
  const Cycles line_transfer = (static_cast<Cycles>(cc.line_bytes) + arch_.memory.dram.bytes_per_cycle - 1) /
                               static_cast<Cycles>(arch_.memory.dram.bytes_per_cycle);
  const bool fill_over_bus = arch_.memory.dram.path == DramPath::bus;

  const FrameSetup<T> setup = setup_frame(scene_, geom_, cmd.frame, cmd.to_world, cmd.camera);
  std::vector<IuRegisters<T>> regs(units);
  trees_.resize(arch_.top_tree() ? units : 0);
  for (std::size_t u = 0; u < units; ++u) {
    regs[u].load(setup, geom_, assignment_[u]);
    if (arch_.top_tree()) out.refit_nodes += load_top(regs[u], trees_[u], assignment_[u], setup, geom_, &out.built_nodes);
  }
  out.refit_cycles = out.refit_nodes * static_cast<std::uint64_t>(arch_.gpp.cycles_per_node);
  g += out.refit_cycles;  // the GPP refits the trees before it writes the registers (Gpp::render_frame)
  for (std::size_t u = 0; u < units; ++u)
    g = transfer(g, assignment_[u].size() * Bytes<T>::sphere_config + regs[u].top.size() * Bytes<T>::top_node);
  const CameraRays camera(cmd.camera, cmd.width, cmd.height);
  const Shader<T> shader(scene_, setup);
  // Caches and pipelines time each visit: they need the records' detail.
  const bool caches = std::find(cached_.begin(), cached_.end(), 1) != cached_.end();
  const bool pipelined = arch_.iu.model == IuModel::pipelined;
  trace_functional(frame_, geom_, regs, camera, shader, arch_, cmd.width, cmd.height, caches || pipelined);
  const FunctionalFrame<T>& f = frame_;

  const std::size_t pixels = static_cast<std::size_t>(cmd.width) * cmd.height;
  std::vector<Cycles> last_pop;  // per ray in issue order: when the last FIFO popped it (FIFO room)
  last_pop.reserve(f.ray_count());
  std::vector<Cycles> unit_free(units, 0);
  // Each frame's time starts at 0 here, and every unit is idle when a frame starts.
  if (pipelined) pipes_.assign(units, PipelinedUnitTiming(pipeline_config(arch_, Bytes<T>::triangle(arch_.kernel))));
  fifo_peak_.resize(units, 0);
  // Per unit: pop times of rays still queued at the latest push (FIFO occupancy in time).
  // A unit pops in push order, so they only grow: a queue kept as a vector and a head.
  struct PopTimes {
    std::vector<Cycles> t;
    std::size_t head = 0;
    std::size_t occupancy_after_push(Cycles at, Cycles pop) {  // rays it holds once this one is in
      while (head < t.size() && t[head] <= at) ++head;
      if (head == t.size()) t.clear(), head = 0;
      else if (head >= 1024 && 2 * head >= t.size()) t.erase(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(head)), head = 0;
      t.push_back(pop);
      return t.size() - head;
    }
  };
  std::vector<PopTimes> queued(units);
  std::uint64_t issued = 0;  // every unit takes every ray
  std::priority_queue<Completion, std::vector<Completion>, std::greater<Completion>> completed;
  std::deque<std::uint32_t> shadow_queue;
  const unsigned depth = static_cast<unsigned>(arch_.fifo_depth);

  // A ray through unit u's cache, visit by visit (IntersectionUnit::trace_through_cache);
  // returns when it ends. The cache's stall is counted in out.units[u].memory.
  VisitStream stream;
  auto entered = [&](std::uint32_t u, const UnitRayWork* w) { return f.visits_of(u, f.units[u].index(w)).size() > 0; };
  auto through_cache = [&](std::uint32_t u, const RayRecord<T>& r, const UnitRayWork& w, Cycles t) {
    auto fetch = [&](std::uint64_t, Cycles q) -> Cycles {
      if (fill_over_bus) q = transfer(q, static_cast<std::uint64_t>(cc.line_bytes));
      return channels[u / per_channel].reserve(q, line_transfer) + static_cast<Cycles>(arch_.memory.dram.latency_cycles);
    };
    const UnitTrace<T>& ut = f.units[u];
    const std::uint32_t i = ut.index(&w);
    std::uint32_t spheres = 0, nodes = 0;
    for (const VisitWork& v : f.visits_of(u, i)) {
      t += std::uint64_t{v.nodes_before} * f.node_cost + std::uint64_t{v.spheres_before} * f.sphere_cost;
      nodes += v.nodes_before;
      spheres += v.spheres_before;
      const WorkCounts again = visit_stream(geom_, regs[u], r.ray, r.kind, v.entry, at, stream);
      t = time_visit(visit_costs(arch_, again), stream, t, caches_[u], windows_[u], out.units[u].memory, fetch,
                     [](int, std::uint64_t) {});
    }
    return t + std::uint64_t{f.node_tests_of(u, i) - nodes} * f.node_cost +
           std::uint64_t{f.sphere_tests_of(u, i) - spheres} * f.sphere_cost;
  };

  // Issue ray `id`: the GPP generates and writes it; every unit takes it in FIFO order.
  const bool simple = !pipelined && !shared && !caches;
  std::vector<Cycles> miss_cycles(units);  // a ray that enters none of the unit's spheres
  for (std::uint32_t u = 0; u < units; ++u) miss_cycles[u] = f.cycles(nullptr, u);
  auto issue = [&](std::uint32_t id) {
    g += arch_.gpp.cycles_per_ray;
    const std::size_t n = last_pop.size();  // rays issued before this one
    if (depth && n >= depth) g = std::max(g, last_pop[n - depth]);  // room in every FIFO
    // Every later request is at or after g (the GPP's time never decreases, and a unit
    // answers after the ray arrived): grants that ended by then can no longer matter.
    bus.forget_before(g);
    for (Calendar<Cycles>& c : channels) c.forget_before(g);
    g = transfer(g, Bytes<T>::ray_bytes(arch_.top_tree()));
    const Cycles avail = g;
    const RayKind kind = f.rays[id].kind;
    ++out.rays[static_cast<int>(kind)];
    const std::uint64_t answer = kind == RayKind::primary ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer;
    Cycles done_all = 0, popped = 0;
    ++issued;
    if (simple) {  // serial units, ideal bus, on-chip memories: the common case, kept tight
      out.bus_transfers += units;
      out.bus_bytes += units * answer;
      for (std::uint32_t u = 0; u < units; ++u) {
        const Cycles start = std::max(unit_free[u], avail);
        const UnitRayWork* w = f.find(id, u);
        const Cycles done = start + (w ? w->cycles : miss_cycles[u]);
        unit_free[u] = done;
        fifo_peak_[u] = std::max<std::uint64_t>(fifo_peak_[u], queued[u].occupancy_after_push(avail, start));
        done_all = std::max(done_all, done);
        popped = std::max(popped, start);
      }
      last_pop.push_back(popped);
      completed.push({done_all, id});
      return;
    }
    for (std::uint32_t u = 0; u < units; ++u) {
      UnitRun& ur = out.units[u];
      const UnitRayWork* w = f.find(id, u);
      Cycles start, done;
      if (pipelined) {
        PipelinedUnitTiming& p = pipes_[u];
        start = std::max(static_cast<Cycles>(p.ready()), avail);
        const auto rv = f.ray_visits(w, u);
        const auto k = p.take(static_cast<Cycle>(start), static_cast<Cycle>(avail), rv.sphere_tests, rv.visits.first,
                              rv.visits.size());
        done = transfer(static_cast<Cycles>(k.done), answer);
        p.retire(k.handle, k.done, static_cast<Cycle>(done));
      } else {
        start = std::max(unit_free[u], avail);
        const Cycles end = cached_[u] && w && entered(u, w) ? through_cache(u, f.rays[id], *w, start)
                                                                    : start + f.cycles(w, u);
        done = transfer(end, answer);
        ur.cycles.stall += done - end;  // the bus; busy cycles are the trace's (below)
        unit_free[u] = done;
      }
      fifo_peak_[u] = std::max<std::uint64_t>(fifo_peak_[u], queued[u].occupancy_after_push(avail, start));
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
  out.per_sphere = f.per_sphere;
  for (std::size_t u = 0; u < units; ++u) {
    out.units[u].fifo_peak = fifo_peak_[u];
    out.units[u].rays = out.units[u].fifo_pushes = out.units[u].fifo_pops = issued;
    if (pipelined) {  // its stages work side by side: each one's issue cycles, and the unit's stalls
      out.units[u].pipeline = pipes_[u].stats();
      out.units[u].cycles = pipelined_cycles(pipes_[u].stats());
      out.units[u].memory.stall = pipes_[u].stats().stage[2].memory;
    } else {
      const std::uint64_t bus_stall = out.units[u].cycles.stall;
      out.units[u].cycles = f.unit_cycles[u];
      if (out.units[u].cache) out.units[u].cycles.stall = out.units[u].memory.stall;  // the cache's, not on-chip memory's
      else out.units[u].memory.stall = f.unit_cycles[u].stall;
      out.units[u].cycles.stall += bus_stall;
    }
    for (int k = 0; k < kRayKinds; ++k) {
      out.units[u].node_tests[k] = f.unit_node_tests[u][k];
      for (std::uint32_t s : assignment_[u]) {
        const WorkCounts& w = f.per_sphere[k][s];
        out.units[u].memory_bytes += w.tri_tests() * Bytes<T>::triangle(arch_.kernel) + w.box_tests * Bytes<T>::node;
      }
    }
  }
  return out;
}

template class AnalyticEngine<float>;
template class AnalyticEngine<double>;

}  // namespace oprt::hw
