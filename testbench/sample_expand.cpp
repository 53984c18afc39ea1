#include "sample_expand.h"

#include "sample_estimate.h"

#include <algorithm>
#include <cmath>

namespace oprt {

std::uint64_t expand_count(std::uint64_t v, double e) { return static_cast<std::uint64_t>(std::llround(static_cast<double>(v) * e)); }

int sampled_fifo_depth(int depth, const PixelSample& s) {
  if (depth <= 0) return depth;
  const double d = depth, w = s.width(), bw = s.block_width(), bh = s.block_height();
  double timed = w / bw;  // one sample row
  if (d <= w) timed = d / bw;
  else if (d >= w * bh) timed = d / (bw * bh);
  return std::max(1, static_cast<int>(std::lround(timed)));
}

namespace {

WorkCounts expand_work(WorkCounts w, double e) {
  w.sphere_tests = expand_count(w.sphere_tests, e);
  w.transforms = expand_count(w.transforms, e);
  for (auto& t : w.tri_stage) t = expand_count(t, e);
  w.tri_hits = expand_count(w.tri_hits, e);
  w.box_setups = expand_count(w.box_setups, e);
  w.box_tests = expand_count(w.box_tests, e);
  w.node_tests = expand_count(w.node_tests, e);
  return w;
}

void expand_pipeline(timing::PipelineStats& p, double e) {
  for (auto& s : p.stage) s.ops = expand_count(s.ops, e), s.busy = expand_count(s.busy, e);
  for (std::uint64_t* x : {&p.occupied, &p.answer_wait, &p.slot_wait, &p.memory_wait, &p.jobs, &p.stack_pushes,
                           &p.stack_spills, &p.stack_fills})
    *x = expand_count(*x, e);
}

void expand_unit(UnitFrameStats& u, double e, std::uint64_t makespan, bool unbounded_fifo) {
  // An unbounded FIFO is sized by its peak. One that held all its rays but a few at once (the
  // GPP wrote them faster than the unit took any) holds all the full frame's but as few; a
  // backlog that grew over the frame (the unit fell behind) grows with it; a FIFO that held a
  // ray or two at a time holds as many in the full frame.
  if (unbounded_fifo) {
    const std::uint64_t taken = u.fifo_pushes - std::min(u.fifo_peak, u.fifo_pushes);
    if (taken <= 1 + u.fifo_pushes / 100) u.fifo_peak = expand_count(u.fifo_pushes, e) - taken;
    else if (u.fifo_peak * 100 > u.fifo_pushes) u.fifo_peak = expand_count(u.fifo_peak, e);
  }
  for (std::uint64_t* x : {&u.rays, &u.memory.hits, &u.memory.misses, &u.memory.dram_bytes, &u.memory.stall,
                           &u.fifo_pushes, &u.fifo_pops, &u.memory_bytes, &u.cycles.sphere, &u.cycles.transform,
                           &u.cycles.primitive, &u.cycles.box, &u.cycles.node, &u.cycles.stall})
    *x = expand_count(*x, e);
  for (auto& w : u.work) w = expand_work(w, e);
  if (u.pipeline) expand_pipeline(*u.pipeline, e);
  const std::uint64_t used = u.pipeline ? u.pipeline->occupied : u.cycles.busy() + u.cycles.stall;
  u.idle = makespan > used ? makespan - used : 0;
}

}  // namespace

FrameStats expand_frame(const FrameStats& fs, double e, std::uint64_t makespan, double frame_time_s, bool unbounded_fifos) {
  FrameStats x = fs;
  for (auto& r : x.rays) r = expand_count(r, e);
  x.makespan = makespan;
  x.frame_time_s = frame_time_s;
  // The bus: the registers and the loads once, the rays' traffic expanded.
  std::uint64_t fixed = fs.memory_load_bytes;
  for (const UnitFrameStats& u : fs.units) fixed += u.config_bytes;
  fixed = std::min(fixed, fs.bus_bytes);
  x.bus_bytes = fixed + expand_count(fs.bus_bytes - fixed, e);
  x.bus_transfers = expand_count(fs.bus_transfers, e);
  x.bus_busy = expand_count(fs.bus_busy, e);
  x.route.cycles = expand_count(fs.route.cycles, e);
  x.route.skipped = expand_count(fs.route.skipped, e);
  for (auto& k : x.route.fanout) k = expand_count(k, e);
  for (auto& u : x.units) expand_unit(u, e, makespan, unbounded_fifos);
  for (auto& c : x.sphere_cycles) c = expand_count(c, e);
  for (auto& s : x.sphere_entries)
    for (auto& k : s) k = expand_count(k, e);
  x.energy.reset();
  return x;
}

MeasuredFrame SampleEstimator::expanded(MeasuredFrame m) const {
  const double e = expansion_;
  for (double& c : m.sphere_cycles) c *= e;
  for (double& t : m.sphere_tests) t *= e;
  for (auto* v : {&m.sphere_slices, &m.unit_node_slices, &m.unit_node_cycles})
    for (std::uint64_t& c : *v) c = expand_count(c, e);
  m.route_cycles = expand_count(m.route_cycles, e);
  m.rays = expand_count(m.rays, e);
  return m;
}

}  // namespace oprt
