// The GPP's plan for a frame, in plain C++: the one place its rules are written. The
// SystemC GPP (hw/gpp.cpp) and the analytic level (analytic/engine.cpp) both follow it; they differ
// only in how they spend time (transactions and waits, or a recurrence).
//  - Object memories (memory_loads): a unit's memory holds its spheres' geometry. The set-up
//    loads every memory before the animation; a frame writes the geometry a unit gains when
//    the assignment moves spheres, and every deforming sphere's. A unit whose spheres exceed
//    memory.sram_bytes uses its memory as a cache in front of DRAM, which holds the whole
//    scene from the set-up on: nothing moves into a cache, and deforming geometry is
//    rewritten in DRAM and dropped from every cache.
//  - Registers (configure): per unit its spheres' world spheres and world -> local matrices
//    for the frame, and with --top bvh its tree over them, rebuilt where the unit's spheres
//    changed (not charged, like choosing the assignment) and refitted every frame
//    (gpp.cycles_per_node per node, before the registers are written).
//  - The frame's functional work (trace), traced once with the units' registers, with the
//    detail that timing through caches, pipelines or a trace needs.
//  - The order of its work (GppWork): a ray whose answers are all in first, then a pending
//    ray its hit spawned (shadow, reflection, refraction: issued only once that hit is
//    shaded), then the next primary ray.
#pragma once

#include "arch/arch.h"
#include "ref/bytes.h"
#include "ref/functional_frame.h"
#include "timing/frame_command.h"
#include "timing/object_memory_model.h"
#include "timing/visit_stream.h"
#include "arch/cycle_schedule.h"
#include "ref/route.h"
#include "ref/frame_setup.h"
#include "scene/scene.h"

#include <deque>
#include <memory>
#include <queue>
#include <utility>
#include <vector>

namespace oprt::timing {

// The GPP's router (--route): a box-test unit's adders and multipliers (route.adders,
// route.multipliers; 0: enough for II 1).
FpUnits router_units(const Arch& a);

template <typename T>
class GppPlan {
 public:
  GppPlan(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch);

  // Spheres per unit, in the units' order; takes effect at the next memory_loads().
  void assign(const std::vector<std::vector<std::uint32_t>>& unit_spheres) { assignment_ = unit_spheres; }
  const std::vector<std::vector<std::uint32_t>>& assignment() const { return assignment_; }
  std::size_t units() const { return assignment_.size(); }

  // The loads this frame needs (the first call: the set-up, every memory), in unit order.
  // Valid until the next call.
  const std::vector<MemoryLoad>& memory_loads();
  bool cached(std::size_t u) const { return u < cached_.size() && cached_[u]; }
  bool any_cached() const;
  // Bytes unit u's spheres occupy (triangles, and BVH nodes).
  std::uint64_t assigned_bytes(std::size_t u) const { return timing::assigned_bytes(geom_, assignment_[u]); }

  // The frame's registers, and the GPP's refit of the units' trees.
  struct Config {
    std::uint64_t refit_nodes = 0, refit_cycles = 0, built_nodes = 0;
    std::vector<std::uint64_t> bytes;  // per unit: its configuration registers written
  };
  const Config& configure(const FrameCommand& cmd);
  const Config& config() const { return config_; }
  const std::vector<IuRegisters<T>>& registers() const { return registers_; }

  // Trace the frame's functional work into `out` (after configure); `traced`: a waveform or
  // a timeline shows each phase. Throws Interrupted on SIGINT / SIGTERM.
  void trace(FunctionalFrame<T>& out, const FrameCommand& cmd, bool traced) const;

  // Routing (ref/route.h): the GPP's router, `lanes` box-test units beside it holding the
  // units' bounds (refitted in configure()), tests a ray against every unit's bound (each
  // lane takes ceil(units / lanes) of them, one issued every II cycles, the last result L
  // cycles after it) and, for `ordered`, sorts the
  // n units whose bound the ray entered by entry distance (n ceil(log2 n) comparisons, one
  // per cycle; the skipped ones among them), before the ray's first wave is written.
  bool routed() const { return arch_.routed(); }
  std::uint64_t route_cycles(std::size_t entered) const;
  const Schedule& router_schedule() const { return router_; }

 private:
  const Scene& scene_;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  std::vector<std::vector<std::uint32_t>> assignment_, loaded_;
  std::vector<char> cached_;
  std::vector<MemoryLoad> loads_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> rewritten_;
  std::vector<IuRegisters<T>> registers_;
  std::vector<TopTree> trees_;
  std::unique_ptr<FrameSetup<T>> setup_;
  Config config_;
  RouteTable<T> route_;
  Schedule router_;
};

// What the dependency of a ray on its parent's answer costs, in a clock's time: per ray kind,
// the rays' latency (issue to last answer) and, for spawned rays, the delay from their
// parent's issue to their own; and the time the GPP had rays in flight but none it could
// issue (every ray left waits for an answer: `starved`).
template <typename Time>
struct Waiting {
  Time latency[kRayKinds] = {}, spawn_delay[kRayKinds] = {};
  Time starved{};
};

// The order of the GPP's work, at either level, in its own time type (sc_time or cycles).
// A routed ray (ref/route.h) goes out in waves: when a wave's answers are all in and the ray
// has another wave, that wave is written next (before pending shadow rays).
// The units a ray's next wave goes to (routed: a range of FunctionalFrame::route_units,
// flagged entries; broadcast: empty, meaning every unit), and whether it is the ray's first.
struct GppWave {
  const std::uint32_t *first = nullptr, *last = nullptr;
  bool initial = true;
  std::size_t size(std::size_t units) const { return first ? static_cast<std::size_t>(last - first) : units; }
};

template <typename T, typename Time>
class GppWork {
 public:
  explicit GppWork(const FunctionalFrame<T>& f)
      : f_(f), pixels_(f.pixel_rays.size() - 1), issued_at_(f.ray_count(), Time{}) {
    if (f.routed) wave_at_.assign(f.route_first.begin(), f.route_first.end() - 1);
  }

  const Waiting<Time>& waiting() const { return waiting_; }

  enum class Next { retire, issue, wait, done };
  // At `now`, with the ray whose answers are all in earliest due at due(), and the next ray
  // writable at `room` (when every ray FIFO it goes to has room; `never` if there is no ray
  // to write): what the GPP does. A completion and a write possible at the same time: the
  // completion.
  // Both clocks call it in every step of their loop, so the time between a call that
  // returned `wait` with no ray to issue and the next call is time the GPP starved.
  Next next(Time now, Time room, Time never, bool all_retired) {
    if (starving_ && now > last_now_) waiting_.starved += now - last_now_;
    last_now_ = now;
    const Next n = choose(now, room, never, all_retired);
    starving_ = n == Next::wait && !has_ray();
    return n;
  }
  bool has_ray() const { return !waves_.empty() || !spawned_.empty() || next_pixel_ < pixels_; }
  // The earliest completion, or `never`, and its ray (when there is one).
  Time due(Time never) const { return completed_.empty() ? never : completed_.top().at; }
  std::uint32_t due_ray() const { return completed_.top().ray; }
  // Ray `id`'s wave has all its answers, the last at `at`.
  void answered(Time at, std::uint32_t id) { completed_.push({at, id}); }
  struct Retired {
    std::uint32_t ray;
    bool shade = false;      // a primary or secondary ray that hit: the GPP shades it
    bool next_wave = false;  // not done: its next wave is queued
  };
  // The completion to handle next. A routed ray with another wave queues it; else the ray
  // is done, and a ray that hit queues the rays its hit spawns.
  Retired retire() {
    const std::uint32_t id = completed_.top().ray;
    const Time at = completed_.top().at;
    completed_.pop();
    if (f_.routed && wave_at_[id] != f_.route_first[id + 1]) {
      waves_.push_back(id);
      return {id, false, true};
    }
    const RayRecord<T>& r = f_.rays[id];
    waiting_.latency[static_cast<int>(r.kind)] += at - issued_at_[id];
    if (!r.hit()) return {id};
    for (std::uint32_t s = id + r.first_child; s < id + r.first_child + r.children; ++s) {
      spawned_.push_back(s);
      issued_at_[s] = issued_at_[id];  // the parent's, until the ray is issued (take_ray)
    }
    return {id, true};
  }
  // The next ray to write: a routed ray's next wave first, then a pending spawned ray.
  std::uint32_t peek_ray() const {
    if (!waves_.empty()) return waves_.front();
    if (!spawned_.empty()) return spawned_.front();
    return f_.pixel_rays[next_pixel_];
  }
  // The next ray, written at `now`.
  std::uint32_t take_ray(Time now) {
    const std::uint32_t id = peek_ray();
    if (!waves_.empty()) {
      waves_.pop_front();
      return id;
    }
    if (!spawned_.empty()) {
      spawned_.pop_front();
      waiting_.spawn_delay[static_cast<int>(f_.rays[id].kind)] += now - issued_at_[id];
    } else {
      ++next_pixel_;
    }
    issued_at_[id] = now;
    return id;
  }
  using Wave = GppWave;
  // How many units' bounds ray `id` entered (routed only).
  std::size_t entered(std::uint32_t id) const { return f_.routed ? f_.route_entered(id) : 0; }
  Wave wave(std::uint32_t id) const {
    if (!f_.routed) return {};
    const std::uint32_t* p = f_.route_units.data() + wave_at_[id];
    const std::uint32_t* end = f_.route_units.data() + f_.route_first[id + 1];
    const std::uint32_t* last = p;
    while (last != end && !(*last++ & kWaveEnd)) {
    }
    return {p, last, wave_at_[id] == f_.route_first[id]};
  }
  // Ray `id`'s next wave is being written.
  void wrote(std::uint32_t id) {
    if (!f_.routed) return;
    wave_at_[id] = static_cast<std::uint32_t>(wave(id).last - f_.route_units.data());
  }

 private:
  Next choose(Time now, Time room, Time never, bool all_retired) const {
    const Time due = completed_.empty() ? never : completed_.top().at;
    const Time next = std::min(due, room);
    if (next == never) return has_ray() || !all_retired ? Next::wait : Next::done;
    if (next > now) return Next::wait;
    return due <= room ? Next::retire : Next::issue;
  }

  struct Completion {
    Time at;
    std::uint32_t ray;
    bool operator>(const Completion& o) const { return at != o.at ? at > o.at : ray > o.ray; }
  };
  const FunctionalFrame<T>& f_;
  const std::size_t pixels_;
  std::size_t next_pixel_ = 0;
  std::priority_queue<Completion, std::vector<Completion>, std::greater<Completion>> completed_;
  std::deque<std::uint32_t> spawned_, waves_;
  std::vector<std::uint32_t> wave_at_;  // routed: where ray r's next wave starts in route_units
  std::vector<Time> issued_at_;         // per ray: when it was issued
  Waiting<Time> waiting_;
  Time last_now_{};
  bool starving_ = false;
};

extern template class GppPlan<float>;
extern template class GppPlan<double>;

}  // namespace oprt::timing
