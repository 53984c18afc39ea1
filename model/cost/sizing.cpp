#include "cost/sizing.h"

#include "ref/bytes.h"
#include "timing/gpp_plan.h"
#include "timing/pipeline_timing.h"

#include <algorithm>

namespace oprt {

namespace {
template <typename T>
StoreBytes store_bytes_of() {
  return {Bytes<T>::ray, 6 * sizeof(T)};
}
}  // namespace

StoreBytes store_bytes(bool double_precision) {
  return double_precision ? store_bytes_of<double>() : store_bytes_of<float>();
}

Design initial_design(const Arch& arch, std::size_t units, std::size_t spheres) {
  Design design;
  const bool dbl = arch.precision == "double";
  design.units.resize(units);
  if (arch.routed()) {
    const FpUnits r = timing::router_units(arch);
    design.router_adders = r.adders * arch.route.lanes;
    design.router_multipliers = r.multipliers * arch.route.lanes;
    design.router_register_bytes = (arch.route.bound == "sphere" ? spheres : units) * 6 * (dbl ? 8 : 4);  // a box each
  }
  design.ray_bytes = ray_bytes(dbl);
  design.double_precision = dbl;
  if (arch.iu.model == IuModel::pipelined) {
    // Its units, each with the adders and multipliers its schedule uses (the box and node
    // units apart: area components of their own); operands move through pipeline
    // registers, so each operation writes its result once (charged as one register-file
    // access: an over-estimate for a pipeline latch) and no register file holds operands.
    // The ray store and the traversal stacks are pipeline_buffers and traversal_stacks.
    const timing::PipelineSchedules p = timing::pipeline_schedules(arch);
    IuUnits iu;
    iu.adders = iu.multipliers = 0;
    iu.register_files = 0;
    iu.register_accesses_per_op = 1;
    for (int s = 0; s < timing::kPipeStages; ++s) {
      if (!p.used[s]) continue;
      const auto stage = static_cast<timing::PipeStage>(s);
      const FpUnits u = timing::stage_units(arch, stage, *p.stage[s].graph);
      int& adders = stage == timing::PipeStage::box ? iu.box_adders : stage == timing::PipeStage::node ? iu.node_adders : iu.adders;
      int& multipliers =
          stage == timing::PipeStage::box ? iu.box_multipliers : stage == timing::PipeStage::node ? iu.node_multipliers : iu.multipliers;
      adders += u.adders;
      multipliers += u.multipliers;
    }
    design.iu = iu;
  }
  return design;
}

OpCounts iu_op_counts(const Arch& arch) {
  if (arch.iu.model != IuModel::pipelined) return op_counts(arch.kernel);
  const timing::PipelineSchedules p = timing::pipeline_schedules(arch);
  return op_counts(arch.kernel, [&p](const OpGraph& g) {
    for (int s = 0; s < timing::kPipeStages; ++s)
      if (p.used[s] && p.stage[s].graph == &g) return p.stage[s];
    return list_schedule(g);  // the box set-up: part of the transform unit's graph
  });
}

void grow_unit(UnitSize& z, const Arch& arch, const timing::UnitRun& r, const UnitHolds& h) {
  const StoreBytes b = store_bytes(arch.precision == "double");
  // A memory that is a cache is memory.sram_bytes, whatever its spheres need.
  const std::uint64_t memory =
      r.cache ? std::min<std::uint64_t>(arch.memory.sram_bytes, h.memory_capacity_bytes) : h.memory_capacity_bytes;
  z.object_memory_bytes = std::max(z.object_memory_bytes, memory);
  z.config_bytes = std::max(z.config_bytes, h.config_bytes);
  // Unbounded: as many entries as it ever held, and one at least if a ray passed through it
  // (a ray popped as soon as it is pushed leaves a peak of 0, yet its write needed a slot).
  const std::uint64_t fifo_entries = arch.fifo_depth > 0 ? static_cast<std::uint64_t>(arch.fifo_depth)
                                                         : std::max<std::uint64_t>(r.fifo_peak, r.fifo_pushes > 0);
  z.fifo_bytes = std::max(z.fifo_bytes, fifo_entries * b.ray);
  if (r.cache) {  // its miss registers: the line's address and data each
    const auto& c = arch.memory.cache;
    z.miss_register_bytes =
        std::max<std::uint64_t>(z.miss_register_bytes, static_cast<std::uint64_t>(c.misses_outstanding) * (8 + c.line_bytes));
  }
  if (r.pipeline) {
    const auto slots = static_cast<std::uint64_t>(arch.iu.rays_in_flight);
    z.buffer_bytes = std::max(z.buffer_bytes, slots * (b.ray + b.local_ray));
    if (arch.accel == "bvh")
      z.stack_bytes = std::max(z.stack_bytes, slots * static_cast<std::uint64_t>(arch.iu.stack_depth) * kStackEntryBytes);
  }
}

UnitActivity unit_activity(const Arch& arch, const timing::UnitRun& r, const UnitHolds& h) {
  const StoreBytes b = store_bytes(arch.precision == "double");
  UnitActivity a;
  for (int k = 0; k < kRayKinds; ++k) a.work += r.work[k];
  a.memory_read_bytes = r.memory_bytes;
  a.memory_write_bytes = r.memory_load_bytes;
  a.fifo_pushes = r.fifo_pushes;
  a.fifo_pops = r.fifo_pops;
  a.config_write_bytes = h.config_bytes;
  if (r.cache) {  // lines from DRAM, written into it; each miss's line written into and read from a miss register
    a.dram_bytes = r.memory.dram_bytes;
    a.memory_write_bytes += r.memory.dram_bytes;
    a.miss_register_access_bytes = 2 * r.memory.misses * static_cast<std::uint64_t>(arch.memory.cache.line_bytes);
  }
  if (r.pipeline) {
    const timing::PipelineStats& p = *r.pipeline;
    // Each ray written into the store; per job the ray read and its local copy written
    // and read. Each push written and read back; a spill or a fill one entry in object memory.
    a.buffer_access_bytes = r.rays * b.ray + p.jobs * (b.ray + 2 * b.local_ray);
    a.stack_access_bytes = 2 * p.stack_pushes * kStackEntryBytes;
    a.memory_write_bytes += p.stack_spills * kStackEntryBytes;
    a.memory_read_bytes += p.stack_fills * kStackEntryBytes;
  }
  return a;
}

FrameActivity frame_activity(const Arch& arch, const timing::FrameFigures& f, double frame_time_s) {
  FrameActivity act;
  act.bus_bytes = f.bus_bytes;
  if (arch.routed()) act.router_tests = f.total_rays() * f.route.bounds;
  act.frame_time_s = frame_time_s;
  return act;
}

}  // namespace oprt
