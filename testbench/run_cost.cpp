#include "run_cost.h"

#include "cost/sizing.h"
#include "tech_default.h"

namespace oprt {

RunCost::RunCost(const std::string& tech_file, const Arch& arch, std::size_t units, std::size_t spheres)
    : arch_(arch), design_(initial_design(arch, units, spheres)), ops_(iu_op_counts(arch)) {
  if (tech_file.empty()) {
    tech_ = tech_from_json(nlohmann::json::parse(kDefaultTech), kDefaultTechFile);
    source_ = kDefaultTechFile;
  } else {
    tech_ = load_tech(tech_file);
    source_ = tech_file;
  }
}

Cost RunCost::frame(const FrameStats& fs) {
  FrameActivity act = frame_activity(arch_, fs, fs.frame_time_s);
  act.units.resize(fs.units.size());
  for (std::size_t u = 0; u < fs.units.size() && u < design_.units.size(); ++u) {
    const UnitFrameStats& s = fs.units[u];
    const UnitHolds holds{s.memory_capacity_bytes, s.config_bytes};
    grow_unit(design_.units[u], arch_, s, holds);
    act.units[u] = unit_activity(arch_, s, holds);
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
