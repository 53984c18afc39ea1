#include "run_cost.h"

#include "timing/bytes.h"
#include "timing/gpp_plan.h"
#include "timing/pipeline_timing.h"
#include "tech_default.h"

#include <algorithm>

namespace oprt {

namespace {
// What a pipelined IU's ray store holds per ray slot: the ray, its local-frame copy, the
// state of its walk; and each entry of its traversal stack (a node index).
struct StoreBytes {
  std::uint64_t ray, local_ray;
};
template <typename T>
StoreBytes store_bytes() {
  return {hw::Bytes<T>::ray, 6 * sizeof(T)};
}
constexpr std::uint64_t kStackEntryBytes = 4;
}  // namespace

RunCost::RunCost(const std::string& tech_file, const Arch& arch, std::size_t units, std::size_t spheres) : arch_(arch) {
  if (tech_file.empty()) {
    tech_ = tech_from_json(nlohmann::json::parse(kDefaultTech), kDefaultTechFile);
    source_ = kDefaultTechFile;
  } else {
    tech_ = load_tech(tech_file);
    source_ = tech_file;
  }
  const bool dbl = arch.precision == "double";
  design_.units.resize(units);
  if (arch.routed()) {
    const FpUnits r = hw::router_units(arch);
    design_.router_adders = r.adders * arch.route.lanes;
    design_.router_multipliers = r.multipliers * arch.route.lanes;
    design_.router_register_bytes = (arch.route.bound == "sphere" ? spheres : units) * 6 * (dbl ? 8 : 4);  // a box each
  }
  design_.ray_bytes = ray_bytes(dbl);
  design_.double_precision = dbl;
  if (arch.iu.model == IuModel::pipelined) {
    // Its units, each with the adders and multipliers its schedule uses (the box and node
    // units apart: area components of their own); operands move through pipeline
    // registers, so each operation writes its result once (charged as one register-file
    // access: an over-estimate for a pipeline latch) and no register file holds operands.
    // The ray store and the traversal stacks are pipeline_buffers and traversal_stacks.
    const hw::PipelineSchedules p = hw::pipeline_schedules(arch);
    IuUnits iu;
    iu.adders = iu.multipliers = 0;
    iu.register_files = 0;
    iu.register_accesses_per_op = 1;
    for (int s = 0; s < hw::kPipeStages; ++s) {
      if (!p.used[s]) continue;
      const auto stage = static_cast<hw::PipeStage>(s);
      const FpUnits u = hw::stage_units(arch, stage, *p.stage[s].graph);
      int& adders = stage == hw::PipeStage::box ? iu.box_adders : stage == hw::PipeStage::node ? iu.node_adders : iu.adders;
      int& multipliers =
          stage == hw::PipeStage::box ? iu.box_multipliers : stage == hw::PipeStage::node ? iu.node_multipliers : iu.multipliers;
      adders += u.adders;
      multipliers += u.multipliers;
    }
    design_.iu = iu;
    ops_ = op_counts(arch.kernel, [&p](const OpGraph& g) {
      for (int s = 0; s < hw::kPipeStages; ++s)
        if (p.used[s] && p.stage[s].graph == &g) return p.stage[s];
      return list_schedule(g);  // the box set-up: part of the transform unit's graph
    });
  } else {
    ops_ = op_counts(arch.kernel);
  }
}

Cost RunCost::frame(const FrameStats& fs) {
  const StoreBytes b = design_.double_precision ? store_bytes<double>() : store_bytes<float>();
  FrameActivity act;
  act.units.resize(fs.units.size());
  act.bus_bytes = fs.bus_bytes;
  if (arch_.routed()) act.router_tests = fs.total_rays() * fs.route.bounds;
  act.frame_time_s = fs.frame_time_s;
  for (std::size_t u = 0; u < fs.units.size() && u < design_.units.size(); ++u) {
    const UnitFrameStats& s = fs.units[u];
    UnitSize& z = design_.units[u];
    // A memory that is a cache is memory.sram_bytes, whatever its spheres need.
    const std::uint64_t memory = s.cache ? std::min<std::uint64_t>(arch_.memory.sram_bytes, s.memory_capacity_bytes)
                                         : s.memory_capacity_bytes;
    z.object_memory_bytes = std::max(z.object_memory_bytes, memory);
    z.config_bytes = std::max(z.config_bytes, s.config_bytes);
    // Unbounded: as many entries as it ever held, and one at least if a ray passed through it
    // (a ray popped as soon as it is pushed leaves a peak of 0, yet its write needed a slot).
    const std::uint64_t fifo_entries = arch_.fifo_depth > 0 ? static_cast<std::uint64_t>(arch_.fifo_depth)
                                                            : std::max<std::uint64_t>(s.fifo_peak, s.fifo_pushes > 0);
    z.fifo_bytes = std::max(z.fifo_bytes, fifo_entries * b.ray);
    UnitActivity& a = act.units[u];
    for (int k = 0; k < kRayKinds; ++k) a.work += s.work[k];
    a.memory_read_bytes = s.memory_bytes;
    a.memory_write_bytes = s.memory_load_bytes;
    a.fifo_pushes = s.fifo_pushes;
    a.fifo_pops = s.fifo_pops;
    a.config_write_bytes = s.config_bytes;
    if (s.cache) {  // lines from DRAM, written into it; its miss registers: the line's address and data each
      const auto& c = arch_.memory.cache;
      a.dram_bytes = s.memory.dram_bytes;
      a.memory_write_bytes += s.memory.dram_bytes;
      z.miss_register_bytes =
          std::max<std::uint64_t>(z.miss_register_bytes, static_cast<std::uint64_t>(c.misses_outstanding) * (8 + c.line_bytes));
      a.miss_register_access_bytes = 2 * s.memory.misses * static_cast<std::uint64_t>(c.line_bytes);
    }
    if (s.pipeline) {
      const hw::PipelineStats& p = *s.pipeline;
      const auto slots = static_cast<std::uint64_t>(arch_.iu.rays_in_flight);
      z.buffer_bytes = std::max(z.buffer_bytes, slots * (b.ray + b.local_ray));
      if (arch_.accel == "bvh")
        z.stack_bytes = std::max(z.stack_bytes, slots * static_cast<std::uint64_t>(arch_.iu.stack_depth) * kStackEntryBytes);
      // Each ray written into the store; per job the ray read and its local copy written
      // and read. Each push written and read back; a spill or a fill one entry in object memory.
      a.buffer_access_bytes = s.rays * b.ray + p.jobs * (b.ray + 2 * b.local_ray);
      a.stack_access_bytes = 2 * p.stack_pushes * kStackEntryBytes;
      a.memory_write_bytes += p.stack_spills * kStackEntryBytes;
      a.memory_read_bytes += p.stack_fills * kStackEntryBytes;
    }
  }
  return frame_energy_j(tech_, design_, ops_, act);
}

nlohmann::json RunCost::header() const {
  nlohmann::json t = {{"file", source_}, {"name", tech_.name}};
  if (tech_.node_nm) t["node_nm"] = *tech_.node_nm;
  return {{"tech", t},
          {"iu_arithmetic", {{"adders", design_.iu.adders},
                             {"multipliers", design_.iu.multipliers},
                             {"comparators", design_.iu.comparators},
                             {"register_files", design_.iu.register_files},
                             {"register_accesses_per_op", design_.iu.register_accesses_per_op}}}};
}

}  // namespace oprt
