#include "run_cost.h"

#include "hw/payloads.h"
#include "timing/pipeline_timing.h"
#include "tech_default.h"

#include <algorithm>

namespace oprt {

namespace {
struct EntryBytes {
  std::uint64_t ray, transform_job, triangle_job;
};
template <typename T>
EntryBytes entry_bytes() {
  return {hw::Bytes<T>::ray, hw::Bytes<T>::transform_job, hw::Bytes<T>::triangle_job};
}
}  // namespace

RunCost::RunCost(const std::string& tech_file, const Arch& arch, std::size_t units) : arch_(arch) {
  if (tech_file.empty()) {
    tech_ = tech_from_json(nlohmann::json::parse(kDefaultTech), kDefaultTechFile);
    source_ = kDefaultTechFile;
  } else {
    tech_ = load_tech(tech_file);
    source_ = tech_file;
  }
  const bool dbl = arch.precision == "double";
  design_.units.resize(units);
  design_.ray_bytes = ray_bytes(dbl);
  design_.double_precision = dbl;
  if (arch.iu.model == IuModel::pipelined) {
    // Three units, each with the adders and multipliers its schedule uses; operands move
    // through pipeline registers, so each operation writes its result once (charged as one
    // register-file access: an over-estimate for a pipeline latch) and no register file
    // holds operands. Rays in flight and queue entries are the pipeline_buffers.
    const hw::PipelineSchedules p = hw::pipeline_schedules(arch);
    IuUnits iu;
    iu.adders = iu.multipliers = 0;
    iu.register_files = 0;
    iu.register_accesses_per_op = 1;
    for (int s = 0; s < hw::kPipeStages; ++s) {
      const FpUnits u = hw::stage_units(arch, static_cast<hw::PipeStage>(s), *p.stage[s].graph);
      iu.adders += u.adders;
      iu.multipliers += u.multipliers;
    }
    design_.iu = iu;
    ops_ = op_counts(arch.kernel, [&p](const OpGraph& g) {
      for (const Schedule& s : p.stage)
        if (s.graph == &g) return s;
      return list_schedule(g);  // the BVH's graphs: not run by a pipelined unit
    });
  } else {
    ops_ = op_counts(arch.kernel);
  }
}

Cost RunCost::frame(const FrameStats& fs) {
  const EntryBytes b = design_.double_precision ? entry_bytes<double>() : entry_bytes<float>();
  const auto depth = static_cast<std::uint64_t>(arch_.iu.queue_depth);
  FrameActivity act;
  act.units.resize(fs.units.size());
  act.bus_bytes = fs.bus_bytes;
  act.frame_time_s = fs.frame_time_s;
  for (std::size_t u = 0; u < fs.units.size() && u < design_.units.size(); ++u) {
    const UnitFrameStats& s = fs.units[u];
    UnitSize& z = design_.units[u];
    z.object_memory_bytes = std::max(z.object_memory_bytes, s.memory_capacity_bytes);
    z.config_bytes = std::max(z.config_bytes, s.config_bytes);
    // Unbounded: as many entries as it ever held, and one at least if a ray passed through it
    // (a ray popped as soon as it is pushed leaves a peak of 0, yet its write needed a slot).
    const std::uint64_t fifo_entries = arch_.fifo_depth > 0 ? static_cast<std::uint64_t>(arch_.fifo_depth)
                                                            : std::max<std::uint64_t>(s.fifo_peak, s.fifo_pushes > 0);
    z.fifo_bytes = std::max(z.fifo_bytes, fifo_entries * b.ray);
    UnitActivity& a = act.units[u];
    a.work = s.work[0];
    a.work += s.work[1];
    a.memory_read_bytes = s.memory_bytes;
    a.memory_write_bytes = s.memory_load_bytes;
    a.fifo_pushes = s.fifo_pushes;
    a.fifo_pops = s.fifo_pops;
    a.config_write_bytes = s.config_bytes;
    if (s.pipeline) {
      const hw::PipelineStats& p = *s.pipeline;
      const std::uint64_t queues = depth ? depth * (b.transform_job + b.triangle_job)
                                         : p.peak_queue[0] * b.transform_job + p.peak_queue[1] * b.triangle_job;
      z.buffer_bytes = std::max(z.buffer_bytes, static_cast<std::uint64_t>(arch_.iu.rays_in_flight) * b.ray + queues);
      // Each ray written into the store of rays in flight; per job the ray read by the
      // transform unit, and one push and one pop in each queue.
      a.buffer_access_bytes = s.rays * b.ray + p.jobs * (b.ray + 2 * b.transform_job + 2 * b.triangle_job);
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
