#include "timing/analytic.h"

#include "timing/calendar.h"
#include "timing/serial_unit_timing.h"

#include <algorithm>
#include <functional>
#include <queue>
#include <set>

namespace oprt::hw {

namespace {
using Cycles = std::uint64_t;

// FIFO occupancy in time: pop times of the rays still queued at the latest push. A unit pops
// in push order, so they only grow: a queue kept as a vector and a head.
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

// Reads through a unit's own object memory model.
struct DirectReader final : VisitReader {
  ObjectMemoryModel* memory = nullptr;
  Cycle read(const VisitStream& s, Cycle request, BurstConsumer& unit) override { return memory->visit(s, request, unit); }
};
}  // namespace

// DRAM channels shared by several units (memory.dram.units_per_channel > 1), or misses over
// the shared bus: each unit's misses reserve their channel's calendar (and the bus's) in the
// order the units' rays are timed (dram.h grants them in time order instead).
template <typename T>
class AnalyticEngine<T>::SharedDram {
 public:
  struct UnitFill final : ObjectMemoryModel::Fill {
    SharedDram* d = nullptr;
    std::uint32_t unit = 0;
    Cycle fetch(std::uint64_t, Cycle t) override { return d->fetch(unit, t); }
  };
  SharedDram(const Arch& a, std::size_t units, std::function<Cycles(Cycles, std::uint64_t)> transfer)
      : a_(a),
        per_channel_(static_cast<std::uint32_t>(a.memory.dram.units_per_channel)),
        channels_(units / per_channel_ + 1),
        fills_(units),
        transfer_(std::move(transfer)),
        line_transfer_((static_cast<Cycles>(a.memory.cache.line_bytes) + a.memory.dram.bytes_per_cycle - 1) /
                       static_cast<Cycles>(a.memory.dram.bytes_per_cycle)) {
    for (std::uint32_t u = 0; u < units; ++u) {
      fills_[u].d = this;
      fills_[u].unit = u;
    }
  }
  ObjectMemoryModel::Fill* fill(std::uint32_t u) { return &fills_[u]; }
  void forget_before(Cycles g) {
    for (auto& c : channels_) c.forget_before(g);
  }
  Cycle fetch(std::uint32_t u, Cycle t) {
    Cycles q = static_cast<Cycles>(t);
    if (a_.memory.dram.path == DramPath::bus) q = transfer_(q, static_cast<std::uint64_t>(a_.memory.cache.line_bytes));
    return static_cast<Cycle>(channels_[u / per_channel_].reserve(q, line_transfer_) +
                              static_cast<Cycles>(a_.memory.dram.latency_cycles));
  }

 private:
  const Arch& a_;
  const std::uint32_t per_channel_;
  std::vector<Calendar<Cycles>> channels_;
  std::vector<UnitFill> fills_;
  std::function<Cycles(Cycles, std::uint64_t)> transfer_;
  const Cycles line_transfer_;
};

template <typename T>
AnalyticEngine<T>::AnalyticEngine(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch)
    : geom_(geometry), arch_(arch), plan_(scene, geometry, arch) {}

template <typename T>
AnalyticEngine<T>::~AnalyticEngine() = default;

template <typename T>
void AnalyticEngine<T>::assign(const Assignment& a) {
  plan_.assign(a.unit);
}

template <typename T>
void AnalyticEngine<T>::make_units(std::size_t units) {
  if (memories_.size() == units) return;
  memories_.clear();
  for (std::size_t u = 0; u < units; ++u)
    memories_.push_back(std::make_unique<ObjectMemoryModel>(arch_, static_cast<std::uint32_t>(u)));
}

template <typename T>
void AnalyticEngine<T>::setup() {
  make_units(plan_.units());
  for (const MemoryLoad& l : plan_.memory_loads()) memories_[l.unit]->load(l);
}

template <typename T>
FrameRun AnalyticEngine<T>::run_frame(const FrameCommand& cmd) {
  const std::size_t units = plan_.units();
  make_units(units);
  FrameRun out;
  out.units.resize(units);
  std::vector<UnitTimed> timed(units);

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
  // Misses contend with other units' (hw/dram.h): the shared channels, per frame.
  std::unique_ptr<SharedDram> frame_dram;
  if (fills_leave_memory(arch_)) frame_dram = std::make_unique<SharedDram>(arch_, units, transfer);

  Cycles g = 0;  // the GPP's time
  // Geometry moved by an assignment change, and deforming geometry, is written into object
  // memory inside the frame (the set-up loaded the rest).
  for (const MemoryLoad& l : plan_.memory_loads()) {
    memories_[l.unit]->load(l);
    out.memory_load_bytes += l.bytes;
    timed[l.unit].memory_load_bytes += l.bytes;
    const Cycles before = g;
    g = transfer(g, l.bytes);
    out.memory_load_cycles += g - before;
  }
  // This frame's time starts at 0: every fill of the last has arrived.
  for (std::size_t u = 0; u < units; ++u) {
    memories_[u]->restart_time();
    memories_[u]->reset_counts();
    memories_[u]->set_fill(frame_dram ? frame_dram->fill(static_cast<std::uint32_t>(u)) : nullptr);
    timed[u].cache = memories_[u]->is_cache();
  }

  const auto& config = plan_.configure(cmd);
  out.refit_nodes = config.refit_nodes;
  out.refit_cycles = config.refit_cycles;
  out.built_nodes = config.built_nodes;
  g += out.refit_cycles;  // the GPP refits the trees before it writes the registers
  for (std::size_t u = 0; u < units; ++u) g = transfer(g, config.bytes[u]);
  plan_.trace(frame_, cmd, false);
  const FunctionalFrame<T>& f = frame_;
  const auto& regs = plan_.registers();

  // Per unit: the rays written into its FIFO and when it popped each (FIFO room: a write
  // needs the pop of the ray `depth` writes before it); kept only with bounded FIFOs.
  const unsigned depth = static_cast<unsigned>(arch_.fifo_depth);
  std::vector<std::uint64_t> pushes(units, 0);
  std::vector<std::vector<Cycles>> pops(depth ? units : 0);
  std::vector<Cycles> unit_free(units, 0);
  // Each frame's time starts at 0 here, and every unit is idle when a frame starts.
  const bool pipelined = arch_.iu.model == IuModel::pipelined;
  if (pipelined) pipes_.assign(units, PipelinedUnitTiming(pipeline_config(arch_)));
  fifo_peak_.resize(units, 0);
  std::vector<PopTimes> queued(units);
  GppWork<T, Cycles> work(f);

  // Rays through caches, and pipelines, read their visits through the unit's memory model.
  const GeometryAddresses<T> addresses(geom_);
  std::vector<CachedVisits<T>> cached;
  cached.reserve(units);
  for (std::size_t u = 0; u < units; ++u) cached.push_back({geom_, regs[u], addresses, arch_, {}, 0});
  PipelineRayBuilder<T> rays(geom_, arch_);
  DirectReader reader;
  auto no_state = [](UnitState, Cycle) {};
  auto no_phase = [](UnitState, Cycle, Cycle) {};
  const Cycle transform = arch_.kernel_costs().transform;

  // A shared bus grants first come first served (hw/bus.h): the units' answers wait here
  // and are granted in the order of their requests, when the GPP's time passes them (before
  // its own writes) or when the GPP waits. A serial unit waits for its answer's transfer, so
  // a ray that reaches it meanwhile waits in its FIFO (`waiting`) and starts when the answer
  // is granted. A pipelined unit's slots free as its answers leave: it takes its next ray
  // once the answers that leave before it could have are granted, which may grant them before
  // a write the GPP makes later in its time but earlier than they: the level's error there.
  struct Pending {
    Cycles at;
    std::uint64_t seq;
    std::uint32_t unit, ray;
    std::uint64_t bytes;
    Cycles end;  // serial: when the unit finished the ray
    PipelinedUnitTiming::Handle handle;
    Cycle done;  // pipelined: when the answer was ready
    bool operator>(const Pending& o) const { return at != o.at ? at > o.at : seq > o.seq; }
  };
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> pending;
  std::vector<std::multiset<Cycles>> unit_pending(units);  // per unit: its answers' requests
  struct Waiting {
    std::uint32_t ray;
    Cycles avail;
  };
  std::vector<std::deque<Waiting>> waiting(units);  // serial: rays in its FIFO while its answer waits
  std::function<void(std::uint32_t, std::uint32_t, Cycles)> start_serial;
  std::vector<std::uint32_t> answers_left(f.ray_count(), 0);
  std::vector<Cycles> ray_done(f.ray_count(), 0);
  std::uint64_t seq = 0;
  auto grant = [&](const Pending& a) {
    const Cycles done = transfer(a.at, a.bytes);
    if (pipelined) {
      pipes_[a.unit].retire(a.handle, a.done, static_cast<Cycle>(done));
    } else {
      timed[a.unit].bus_stall += done - a.end;
      unit_free[a.unit] = done;
    }
    unit_pending[a.unit].erase(unit_pending[a.unit].find(a.at));
    ray_done[a.ray] = std::max(ray_done[a.ray], done);
    if (--answers_left[a.ray] == 0) work.answered(ray_done[a.ray], a.ray);
    if (!pipelined && !waiting[a.unit].empty()) {  // the next ray in its FIFO
      const Waiting w = waiting[a.unit].front();
      waiting[a.unit].pop_front();
      start_serial(a.unit, w.ray, w.avail);
    }
  };
  auto grant_until = [&](Cycles t) {  // every answer requested at or before t
    while (!pending.empty() && pending.top().at <= t) {
      const Pending a = pending.top();
      pending.pop();
      grant(a);
    }
  };
  // Unit u's answers requested at or before t (and, first, everything requested before them).
  auto grant_unit_until = [&](std::uint32_t u, Cycles t) {
    while (!unit_pending[u].empty() && *unit_pending[u].begin() <= t) grant_until(*unit_pending[u].begin());
  };

  // Issue ray `id`: the GPP generates and writes it; every unit takes it in FIFO order.
  const bool caches = plan_.any_cached();
  const bool simple = !pipelined && !shared && !caches;
  std::vector<Cycles> miss_cycles(units);  // a ray that enters none of the unit's spheres
  for (std::uint32_t u = 0; u < units; ++u) miss_cycles[u] = f.cycles(nullptr, u);
  // When the FIFOs of the units the next write goes to have room (as the SystemC GPP reads it
  // off its FIFOs); `unknown` while one of them has yet to pop the ray whose slot the write
  // needs (it waits for its answer's transfer).
  constexpr Cycles unknown = ~Cycles{0} - 1;
  auto fifo_room = [&](std::uint32_t u) -> Cycles {
    if (!depth || pushes[u] < depth) return 0;
    const std::uint64_t k = pushes[u] - depth;
    return k < pops[u].size() ? pops[u][k] : unknown;
  };
  auto room_time = [&]() {
    Cycles t = g;
    if (!depth) return t;
    const auto wave = work.wave(work.peek_ray());
    if (!wave.first) {
      for (std::uint32_t u = 0; u < units; ++u) t = std::max(t, fifo_room(u));
    } else {
      for (const std::uint32_t* p = wave.first; p != wave.last; ++p) t = std::max(t, fifo_room(*p & ~kWaveEnd));
    }
    return t;
  };
  auto popped = [&](std::uint32_t u, Cycles avail, Cycles start) {
    fifo_peak_[u] = std::max<std::uint64_t>(fifo_peak_[u], queued[u].occupancy_after_push(avail, start));
    if (depth) pops[u].push_back(start);
  };
  auto answer_bytes = [&](std::uint32_t id) -> std::uint64_t {
    return f.rays[id].kind == RayKind::primary ? Bytes<T>::nearest_answer : Bytes<T>::shadow_answer;
  };
  // A serial unit starts ray `id` (arrived at `avail`) when it is free: its time on it, then
  // its answer (at once on an ideal bus; granted in order on a shared one).
  start_serial = [&](std::uint32_t u, std::uint32_t id, Cycles avail) {
    const UnitRayWork* w = f.find(id, u);
    const Cycles start = std::max(unit_free[u], avail);
    reader.memory = memories_[u].get();
    const bool through_cache = timed[u].cache;
    if (through_cache) memories_[u]->forget_before(static_cast<Cycle>(start));
    // On-chip memory: the trace holds the ray's cycles. Through a cache: visit by visit.
    const Cycles end = !through_cache ? start + f.cycles(w, u)
                                      : static_cast<Cycles>(serial_ray(
                                            f, u, w, static_cast<Cycle>(start), transform, true,
                                            [&](const VisitWork& v, Cycle t) {
                                              return cached_visit(
                                                  cached[u], f.rays[id], v, t,
                                                  [&](const VisitStream& s, Cycle r, BurstConsumer& c) {
                                                    return reader.read(s, r, c);
                                                  },
                                                  no_state);
                                            },
                                            no_phase));
    popped(u, avail, start);
    if (shared) {
      pending.push({end, seq++, u, id, answer_bytes(id), end, 0, 0});
      unit_pending[u].insert(end);
      return;
    }
    const Cycles done = transfer(end, answer_bytes(id));
    unit_free[u] = done;
    ray_done[id] = std::max(ray_done[id], done);
    if (--answers_left[id] == 0) work.answered(ray_done[id], id);
  };
  // Write ray `id`'s next wave (every unit when broadcast): the GPP generates and routes a
  // new ray first; every unit of the wave takes it in FIFO order.
  const bool mask = arch_.route.transfer == "mask";
  const std::uint64_t mask_bytes = (units + 7) / 8;
  auto issue = [&](std::uint32_t id) {
    const auto wave = work.wave(id);
    const std::size_t n = wave.size(units);
    if (wave.initial) {
      g += arch_.gpp.cycles_per_ray;  // room first (the GPP's rule waited for it), then the ray is generated
      const std::uint64_t route = plan_.route_cycles(work.entered(id));
      g += route;
      out.route.cycles += route;
    }
    work.wrote(id);
    const RayKind kind = f.rays[id].kind;
    if (wave.initial) ++out.rays[static_cast<int>(kind)];
    answers_left[id] = static_cast<std::uint32_t>(n);
    if (n == 0) {  // routed to no unit: the router's answer is the ray's
      work.answered(g, id);
      return;
    }
    if (shared) grant_until(g);  // answers requested before the GPP's write take the bus first
    // Every later request is at or after g (the GPP's time never decreases, and a unit
    // answers after the ray arrived): grants that ended by then can no longer matter.
    bus.forget_before(g);
    if (frame_dram) frame_dram->forget_before(g);
    const std::uint64_t ray_bytes = Bytes<T>::ray_bytes(arch_.top_tree());
    if (!wave.first) g = transfer(g, ray_bytes);
    else if (mask) g = transfer(g, ray_bytes + mask_bytes);
    else for (std::size_t i = 0; i < n; ++i) g = transfer(g, ray_bytes);
    const Cycles avail = g;
    if (simple && !wave.first) {  // serial units, ideal bus, on-chip memories, broadcast: kept tight
      const std::uint64_t answer = answer_bytes(id);
      out.bus_transfers += units;
      out.bus_bytes += units * answer;
      Cycles done_all = 0;
      for (std::uint32_t u = 0; u < units; ++u) {
        const Cycles start = std::max(unit_free[u], avail);
        const UnitRayWork* w = f.find(id, u);
        const Cycles done = start + (w ? w->cycles : miss_cycles[u]);
        unit_free[u] = done;
        ++pushes[u];
        popped(u, avail, start);
        done_all = std::max(done_all, done);
      }
      work.answered(done_all, id);
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t u = wave.first ? wave.first[i] & ~kWaveEnd : static_cast<std::uint32_t>(i);
      ++pushes[u];
      if (!pipelined) {
        if (shared && (!unit_pending[u].empty() || !waiting[u].empty())) waiting[u].push_back({id, avail});
        else start_serial(u, id, avail);
        continue;
      }
      PipelinedUnitTiming& p = pipes_[u];
      const UnitRayWork* w = f.find(id, u);
      reader.memory = memories_[u].get();
      // Its slots free as its answers leave: those that leave by the time it could take the ray.
      Cycles start;
      for (;;) {
        start = std::max(static_cast<Cycles>(p.ready()), avail);
        if (unit_pending[u].empty() || *unit_pending[u].begin() > start) break;
        grant_unit_until(u, *unit_pending[u].begin());
      }
      memories_[u]->forget_before(static_cast<Cycle>(start));
      const auto k = p.take(static_cast<Cycle>(start), static_cast<Cycle>(avail), rays.build(f, u, w, id, regs[u]), reader);
      popped(u, avail, start);
      if (shared) {
        pending.push({static_cast<Cycles>(k.done), seq++, u, id, answer_bytes(id), 0, k.handle, k.done});
        unit_pending[u].insert(static_cast<Cycles>(k.done));
      } else {
        const Cycles done = transfer(static_cast<Cycles>(k.done), answer_bytes(id));
        p.retire(k.handle, k.done, static_cast<Cycle>(done));
        ray_done[id] = std::max(ray_done[id], done);
        if (--answers_left[id] == 0) work.answered(ray_done[id], id);
      }
    }
  };

  // The GPP's work in its order (GppWork), as the SystemC GPP does it: a completion due, else
  // the next ray once every FIFO has room, else wait for whichever comes first.
  constexpr Cycles never = ~Cycles{0};
  for (;;) {
    grant_until(g);
    const Cycles room = work.has_ray() ? room_time() : never;
    if (room == unknown) {  // a unit has yet to pop the ray whose slot the next one needs
      grant_until(pending.top().at);
      continue;
    }
    const auto next = work.next(g, room, never, work.due(never) == never && pending.empty());
    if (next == GppWork<T, Cycles>::Next::done) break;
    if (next == GppWork<T, Cycles>::Next::retire) {
      if (work.retire().shade) g += arch_.gpp.cycles_per_hit;
    } else if (next == GppWork<T, Cycles>::Next::issue) {
      issue(work.take_ray());
    } else {
      const Cycles t = std::min(work.due(never), room);
      if (!pending.empty() && pending.top().at <= t) grant_until(pending.top().at);  // may complete a ray earlier
      else g = t;  // the GPP waits
    }
  }
  out.makespan = g;
  route_figures(f, units, out.route);
  *cmd.image = f.image;
  report_work(f, out);
  for (std::size_t u = 0; u < units; ++u) {
    UnitTimed& t = timed[u];
    t.rays = t.fifo_pushes = t.fifo_pops = pushes[u];
    t.fifo_peak = fifo_peak_[u];
    t.memory = memories_[u]->counts();
    t.cache_stall = cached[u].stall;
    if (pipelined) t.pipeline = pipes_[u].stats();
    out.units[u] = unit_run(f, static_cast<std::uint32_t>(u), plan_.assignment()[u], geom_, arch_, t);
  }
  return out;
}

template class AnalyticEngine<float>;
template class AnalyticEngine<double>;

}  // namespace oprt::hw
