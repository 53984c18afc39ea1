// What a frame measured, per unit and in all: the one place a unit's figures are made from
// its work (the functional trace) and what the level timed. The SystemC testbench and the
// analytic level both fill a FrameRun this way; the stats writer reads it.
//
// Each figure is declared once, here, and carried by whole structs from the level that
// counts it to stats.json: GppFigures (hw/gpp.h's GppStats, the analytic GPP) and
// FrameFigures into FrameRun and on into FrameStats (testbench/stats.h); UnitCounts (what a
// level timed of a unit) into UnitRun and on into UnitFrameStats. A new figure is a member
// of one of them and a line in the stats writer (testbench/stats.cpp), nothing between.
#pragma once

#include "arch/arch.h"
#include "timing/cache.h"
#include "ref/functional_frame.h"
#include "timing/pipeline_timing.h"
#include "timing/ray_figures.h"
#include "timing/sample_figures.h"
#include "ref/work.h"

#include <array>
#include <optional>
#include <vector>

namespace oprt::timing {

// The sum over ray kinds of a per-kind figure.
inline std::uint64_t all_kinds(const std::uint64_t (&per_kind)[kRayKinds]) {
  std::uint64_t n = 0;
  for (int k = 0; k < kRayKinds; ++k) n += per_kind[k];
  return n;
}

// What a level counted of one unit in a frame, beside the trace's work.
struct UnitCounts {
  std::uint64_t rays = 0;
  bool cache = false;  // its spheres did not fit its object memory (memory.sram_bytes)
  CacheCounts memory;  // through the cache: lines hit and missed, bytes from DRAM; stall: the memory's, whichever it is
  std::uint64_t memory_load_bytes = 0;      // geometry loaded into its object memory this frame
  std::uint64_t fifo_pushes = 0, fifo_pops = 0;
  std::uint64_t fifo_peak = 0;              // most rays its FIFO held at once, over the run so far
  std::optional<PipelineStats> pipeline;    // a pipelined unit's stages
};

// A unit's figures in a frame: what was counted, and what its work (the trace's) made of it.
struct UnitRun : UnitCounts {
  UnitCycles cycles;
  std::uint64_t memory_bytes = 0;
  WorkCounts work[kRayKinds];  // its sphere visits' work (ref/work.h), and node_tests: its tree's (--top bvh)
  std::uint64_t assigned_bytes = 0;  // the bytes its spheres need in its object memory
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

// What the GPP counts in a frame (the SystemC Gpp's GppStats, the analytic GPP).
struct GppFigures {
  std::uint64_t rays[kRayKinds] = {};
  std::uint64_t memory_load_bytes = 0;   // geometry moved into object memories this frame
  std::uint64_t memory_load_cycles = 0;  // bus time of that move, inside the makespan (0 on an ideal bus)
  // --top bvh: nodes of the units' trees over their spheres refitted this frame, the GPP's
  // cycles for that, and nodes built anew (the assignment changed) (gpp_plan.h)
  std::uint64_t refit_nodes = 0, refit_cycles = 0, built_nodes = 0;
  // The frame's start (those loads, the refit, the registers written): cycles from the frame's
  // beginning to its first ray (the same in a sampled run as in the full one).
  std::uint64_t start_cycles = 0;

  std::uint64_t total_rays() const { return all_kinds(rays); }
};

// A frame's figures in all.
struct FrameFigures : GppFigures {
  std::uint64_t makespan = 0;  // cycles from the frame's first configuration write to its last retired ray
  std::uint64_t bus_busy = 0, bus_bytes = 0, bus_transfers = 0;
  RouteRun route;  // --route: the router's cycles, spared (ray, unit) pairs, fan-out histogram
  RayFigures ray_figures;  // per ray kind and depth: fan-out, bytes, latency (ray_figures.h)
};

struct FrameRun : FrameFigures {
  std::optional<SampleFrame> sample;  // --sample: the figures per traced pixel (sample_figures.h)
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

// What a level timed of one unit in a frame: its counts, and the stalls that make its cycles.
struct UnitTimed : UnitCounts {
  std::uint64_t bus_stall = 0;  // a serial unit waiting for the bus to take its answers
  std::uint64_t cache_stall = 0;  // through a cache: its stall replaces the trace's (on-chip memory's)
};

// Unit u's figures: busy cycles by activity from the trace (a pipelined unit: its stages'),
// stalls from what was timed, bytes read from its spheres' work.
template <typename T>
UnitRun unit_run(const FunctionalFrame<T>& f, std::uint32_t u, const std::vector<std::uint32_t>& spheres,
                 const SceneGeometry<T>& g, const Arch& a, const UnitTimed& t) {
  UnitRun r;
  static_cast<UnitCounts&>(r) = t;
  r.cycles = f.unit_cycles[u];
  if (t.pipeline) {  // its stages work side by side: each one's issue cycles, and the unit's stalls
    r.cycles = pipelined_cycles(*t.pipeline);
    r.memory.stall = t.pipeline->memory_wait;
  } else {
    if (t.cache) r.cycles.stall = t.cache_stall;  // the cache's, not on-chip memory's
    r.memory.stall = r.cycles.stall;
    r.cycles.stall += t.bus_stall;
  }
  r.assigned_bytes = assigned_bytes(g, spheres);
  for (int k = 0; k < kRayKinds; ++k) {
    r.work[k] = f.unit_work[u][k];  // the unit's share of a replicated sphere's work, not all of it
    r.work[k].node_tests = f.unit_node_tests[u][k];  // the unit's, never a sphere's
    const WorkCounts& w = f.unit_work[u][k];
    r.memory_bytes += w.tri_tests() * Bytes<T>::triangle(a.kernel) + w.box_tests * Bytes<T>::node;
  }
  return r;
}

}  // namespace oprt::timing
