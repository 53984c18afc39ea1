// What a frame measured, per unit and in all: the one place a unit's figures are made from
// its work (the functional trace) and what the level timed. The SystemC testbench and the
// analytic level both fill a FrameRun this way; the stats writer reads it.
#pragma once

#include "arch/arch.h"
#include "timing/cache.h"
#include "timing/functional_frame.h"
#include "timing/pipeline_timing.h"
#include "timing/ray_figures.h"
#include "timing/unit_cycles.h"

#include <array>
#include <optional>
#include <vector>

namespace oprt::hw {

struct UnitRun {
  UnitCycles cycles;
  std::uint64_t rays = 0;
  std::uint64_t memory_bytes = 0;
  std::uint64_t node_tests[kRayKinds] = {};  // --top bvh
  WorkCounts work[kRayKinds];                 // its sphere visits' work (ref/work.h)
  bool cache = false;  // its spheres did not fit its object memory (memory.sram_bytes)
  std::uint64_t assigned_bytes = 0;
  CacheCounts memory;  // through the cache; stall: the memory's, whichever it is
  std::uint64_t memory_load_bytes = 0;      // geometry loaded into its object memory this frame
  std::uint64_t fifo_pushes = 0, fifo_pops = 0;
  std::uint64_t fifo_peak = 0;              // most rays its FIFO held at once, over the run so far
  std::optional<PipelineStats> pipeline;    // a pipelined unit's stages
};

// Routing (ref/route.h): the router's cycles, the (ray, unit) pairs `ordered` spared, and
// the rays by how many units they went to (fanout[k]: rays sent to k units).
struct RouteRun {
  std::uint64_t cycles = 0, skipped = 0;
  std::uint64_t bounds = 0;  // boxes the router tests each ray against (a unit's, or its spheres')
  std::vector<std::uint64_t> fanout;
};

// The fan-out histogram and the spared pairs of a frame, from its trace.
template <typename T>
void route_figures(const FunctionalFrame<T>& f, std::size_t units, RouteRun& r) {
  r.fanout.assign(units + 1, 0);
  r.bounds = f.route_bounds;
  if (!f.routed) {
    r.fanout[units] = f.ray_count();
    return;
  }
  for (std::uint32_t id = 0; id < f.ray_count(); ++id) ++r.fanout[f.route_first[id + 1] - f.route_first[id]];
  r.skipped = f.skipped;
}

struct FrameRun {
  std::uint64_t makespan = 0;
  std::uint64_t rays[kRayKinds] = {};
  std::uint64_t bus_busy = 0, bus_bytes = 0, bus_transfers = 0, memory_load_bytes = 0;
  std::uint64_t memory_load_cycles = 0;  // bus time of the geometry moved in (0 on an ideal bus)
  std::uint64_t refit_nodes = 0, refit_cycles = 0, built_nodes = 0;  // --top bvh: the GPP's refit (gpp_plan.h)
  RouteRun route;
  RayFigures ray_figures;  // per kind and depth (ray_figures.h)
  std::vector<UnitRun> units;
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;  // [kind][sphere], whichever unit did it
  std::vector<std::uint64_t> sphere_slices, unit_node_slices;  // FunctionalFrame's: when the work lay in the frame
};

// The rays' figures of a frame (ray_figures.h): the counts from its trace, the times from
// the GPP's Waiting converted to cycles by `cycles`.
template <typename T, typename Time, typename ToCycles>
void ray_figures(const FunctionalFrame<T>& f, const Arch& a, std::size_t units, const Waiting<Time>& w,
                 ToCycles&& cycles, RayFigures& out) {
  count_ray_figures(f, a, units, out);
  for (int k = 0; k < kRayKinds; ++k) {
    out.kind[k].latency = cycles(w.latency[k]);
    out.kind[k].spawn_delay = cycles(w.spawn_delay[k]);
  }
  out.starved = cycles(w.starved);
}

// The frame's work tables a run reports (for the next frame's balance).
template <typename T>
void report_work(const FunctionalFrame<T>& f, FrameRun& run) {
  run.per_sphere = f.per_sphere;
  run.sphere_slices = f.sphere_slices;
  run.unit_node_slices = f.unit_node_slices;
}

// What a level timed of one unit in a frame, beside the trace's work.
struct UnitTimed {
  std::uint64_t rays = 0;
  std::uint64_t bus_stall = 0;  // a serial unit waiting for the bus to take its answers
  bool cache = false;
  CacheCounts memory;           // through a cache: lines hit and missed, bytes from DRAM
  std::uint64_t cache_stall = 0;  // through a cache: its stall replaces the trace's (on-chip memory's)
  std::optional<PipelineStats> pipeline;
  std::uint64_t fifo_pushes = 0, fifo_pops = 0, fifo_peak = 0;
  std::uint64_t memory_load_bytes = 0;
};

// Unit u's figures: busy cycles by activity from the trace (a pipelined unit: its stages'),
// stalls from what was timed, bytes read from its spheres' work.
template <typename T>
UnitRun unit_run(const FunctionalFrame<T>& f, std::uint32_t u, const std::vector<std::uint32_t>& spheres,
                 const SceneGeometry<T>& g, const Arch& a, const UnitTimed& t) {
  UnitRun r;
  r.cycles = f.unit_cycles[u];
  r.cache = t.cache;
  r.memory = t.memory;
  if (t.pipeline) {  // its stages work side by side: each one's issue cycles, and the unit's stalls
    r.cycles = pipelined_cycles(*t.pipeline);
    r.memory.stall = t.pipeline->memory_wait;
  } else {
    if (t.cache) r.cycles.stall = t.cache_stall;  // the cache's, not on-chip memory's
    r.memory.stall = r.cycles.stall;
    r.cycles.stall += t.bus_stall;
  }
  r.pipeline = t.pipeline;
  r.rays = t.rays;
  r.fifo_pushes = t.fifo_pushes;
  r.fifo_pops = t.fifo_pops;
  r.fifo_peak = t.fifo_peak;
  r.memory_load_bytes = t.memory_load_bytes;
  r.assigned_bytes = assigned_bytes(g, spheres);
  for (int k = 0; k < kRayKinds; ++k) {
    r.node_tests[k] = f.unit_node_tests[u][k];
    r.work[k] = f.unit_work[u][k];
    const WorkCounts& w = f.unit_work[u][k];
    r.memory_bytes += w.tri_tests() * Bytes<T>::triangle(a.kernel) + w.box_tests * Bytes<T>::node;
  }
  return r;
}

}  // namespace oprt::hw
