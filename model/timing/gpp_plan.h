// The GPP's plan for a frame, in plain C++: the one place its rules are written. The
// SystemC GPP (hw/gpp.cpp) and the analytic level (analytic.cpp) both follow it; they differ
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
//    shadow ray, then the next primary ray.
#pragma once

#include "arch/arch.h"
#include "timing/bytes.h"
#include "timing/functional_frame.h"
#include "timing/object_memory_model.h"
#include "timing/visit_stream.h"
#include "ref/frame_setup.h"
#include "scene/scene.h"

#include <deque>
#include <memory>
#include <queue>
#include <utility>
#include <vector>

namespace oprt::hw {

template <typename T>
class GppPlan {
 public:
  GppPlan(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch)
      : scene_(scene), geom_(geometry), arch_(arch) {}

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
  std::uint64_t assigned_bytes(std::size_t u) const { return hw::assigned_bytes(geom_, assignment_[u]); }

  // The frame's registers, and the GPP's refit of the units' trees.
  struct Config {
    std::uint64_t refit_nodes = 0, refit_cycles = 0, built_nodes = 0;
    std::vector<std::uint64_t> bytes;  // per unit: its configuration registers written
  };
  const Config& configure(const FrameCommand& cmd);
  const std::vector<IuRegisters<T>>& registers() const { return registers_; }

  // Trace the frame's functional work into `out` (after configure); `traced`: a waveform or
  // a timeline shows each phase. Throws Interrupted on SIGINT / SIGTERM.
  void trace(FunctionalFrame<T>& out, const FrameCommand& cmd, bool traced) const;

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
};

// The order of the GPP's work, at either level, in its own time type (sc_time or cycles).
template <typename T, typename Time>
class GppWork {
 public:
  explicit GppWork(const FunctionalFrame<T>& f) : f_(f), pixels_(f.pixel_rays.size() - 1) {}

  enum class Next { retire, issue, wait, done };
  // At `now`, with the ray whose answers are all in earliest due at due(), and the next ray
  // writable at `room` (when every ray FIFO has room; `never` if there is no ray to write):
  // what the GPP does. A completion and a write possible at the same time: the completion.
  Next next(Time now, Time room, Time never, bool all_retired) const {
    const Time due = completed_.empty() ? never : completed_.top().at;
    const Time next = std::min(due, room);
    if (next == never) return has_ray() || !all_retired ? Next::wait : Next::done;
    if (next > now) return Next::wait;
    return due <= room ? Next::retire : Next::issue;
  }
  bool has_ray() const { return !shadow_.empty() || next_pixel_ < pixels_; }
  // The earliest completion, or `never`.
  Time due(Time never) const { return completed_.empty() ? never : completed_.top().at; }
  // Ray `id` has all its answers, the last at `at`.
  void answered(Time at, std::uint32_t id) { completed_.push({at, id}); }
  // The completion to handle next; a primary ray that hit queues its shadow rays. Returns
  // (ray, whether it is a primary that hit: the GPP shades it).
  std::pair<std::uint32_t, bool> retire() {
    const std::uint32_t id = completed_.top().ray;
    completed_.pop();
    const RayRecord<T>& r = f_.rays[id];
    if (r.kind != RayKind::primary || f_.image.object[r.pixel] == kNone) return {id, false};
    for (std::uint32_t s = id + 1; s < f_.pixel_rays[r.pixel + 1]; ++s) shadow_.push_back(s);
    return {id, true};
  }
  // The next ray to write: a pending shadow ray first.
  std::uint32_t take_ray() {
    if (!shadow_.empty()) {
      const std::uint32_t id = shadow_.front();
      shadow_.pop_front();
      return id;
    }
    return f_.pixel_rays[next_pixel_++];
  }

 private:
  struct Completion {
    Time at;
    std::uint32_t ray;
    bool operator>(const Completion& o) const { return at != o.at ? at > o.at : ray > o.ray; }
  };
  const FunctionalFrame<T>& f_;
  const std::size_t pixels_;
  std::size_t next_pixel_ = 0;
  std::priority_queue<Completion, std::vector<Completion>, std::greater<Completion>> completed_;
  std::deque<std::uint32_t> shadow_;
};

extern template class GppPlan<float>;
extern template class GppPlan<double>;

}  // namespace oprt::hw
