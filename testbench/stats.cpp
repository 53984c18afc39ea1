#include "stats.h"

#include "ref/image.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace oprt {

std::uint64_t FrameStats::busy() const {
  std::uint64_t b = 0;
  for (const auto& u : units) b += u.cycles.busy();
  return b;
}

double FrameStats::efficiency() const {
  return makespan && !units.empty() ? static_cast<double>(busy()) / (static_cast<double>(units.size()) * makespan) : 0;
}

double FrameStats::idle_fraction() const {
  std::uint64_t idle = 0;
  for (const auto& u : units) idle += u.idle;
  return makespan && !units.empty() ? static_cast<double>(idle) / (static_cast<double>(units.size()) * makespan) : 0;
}

namespace {
nlohmann::json work_json(const WorkCounts& w) {
  return {{"sphere_tests", w.sphere_tests},
          {"transforms", w.transforms},
          {"triangle_tests", w.tri_tests()},
          {"triangle_exit_stage", {w.tri_stage[0], w.tri_stage[1], w.tri_stage[2], w.tri_stage[3]}},
          {"triangle_hits", w.tri_hits},
          {"box_setups", w.box_setups},
          {"box_tests", w.box_tests},
          {"node_tests", w.node_tests}};
}
}  // namespace

nlohmann::json to_json(const FrameStats& f) {
  nlohmann::json units = nlohmann::json::array();
  for (const UnitFrameStats& u : f.units) {
    units.push_back({{"id", u.id},
                     {"spheres", u.spheres},
                     {"primitives", u.primitives},
                     {"rays", u.rays},
                     {"cycles", {{"sphere", u.cycles.sphere},
                                 {"transform", u.cycles.transform},
                                 {"primitive", u.cycles.primitive},
                                 {"box", u.cycles.box},
                                 {"node", u.cycles.node},
                                 {"idle", u.idle},
                                 {"stall", u.cycles.stall}}},
                     {"busy_cycles", u.cycles.busy()},
                     {"memory_bytes_read", u.memory_bytes},
                     {"memory", {{"cache", u.cache},
                                 {"assigned_bytes", u.assigned_bytes},
                                 {"hits", u.memory.hits},
                                 {"misses", u.memory.misses},
                                 {"dram_bytes", u.memory.dram_bytes},
                                 {"stall_cycles", u.memory.stall}}},
                     {"work", {{"primary", work_json(u.work[0])}, {"shadow", work_json(u.work[1])}}}});
  }
  const double rays = static_cast<double>(f.rays[0] + f.rays[1]);
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(f.image_hash));
  return {{"frame", f.frame},
          {"makespan_cycles", f.makespan},
          {"parallel_efficiency", f.efficiency()},
          {"idle_fraction", f.idle_fraction()},
          {"busy_cycles", f.busy()},
          {"wall_s", f.wall_s},
          {"rays", {{"primary", f.rays[0]}, {"shadow", f.rays[1]}}},
          {"rays_per_wall_s", f.wall_s > 0 ? rays / f.wall_s : 0},
          {"bus", {{"busy_cycles", f.bus_busy}, {"bytes", f.bus_bytes}, {"transfers", f.bus_transfers}}},
          {"memory_load_bytes", f.memory_load_bytes},
          {"memory_load_cycles", f.memory_load_cycles},
          {"gpp", {{"refit_nodes", f.refit_nodes}, {"refit_cycles", f.refit_cycles}, {"nodes_built", f.built_nodes}}},
          {"image_hash", hash},
          {"sphere_cycles", f.sphere_cycles},
          {"sphere_entries", f.sphere_entries},
          {"ius", units}};
}

StatsWriter::StatsWriter(std::string dir, nlohmann::json header) : dir_(std::move(dir)), doc_(std::move(header)) {}

void StatsWriter::add(const FrameStats& f) {
  frames_.push_back(f);
  nlohmann::json frames = nlohmann::json::array();
  double wall = 0, eff = 0, idle = 0;
  std::uint64_t makespan = 0, rays = 0, busy = 0, load_bytes = 0, load_cycles = 0, refit_cycles = 0;
  for (const FrameStats& x : frames_) {
    frames.push_back(to_json(x));
    wall += x.wall_s;
    eff += x.efficiency();
    idle += x.idle_fraction();
    makespan += x.makespan;
    busy += x.busy();
    rays += x.rays[0] + x.rays[1];
    load_bytes += x.memory_load_bytes;
    load_cycles += x.memory_load_cycles;
    refit_cycles += x.refit_cycles;
  }
  nlohmann::json doc = doc_;
  doc["summary"] = {{"frames", frames_.size()},
                    {"makespan_cycles_total", makespan},
                    {"parallel_efficiency_mean", eff / frames_.size()},
                    {"idle_fraction_mean", idle / frames_.size()},
                    {"busy_cycles_total", busy},
                    {"memory_load_bytes_total", load_bytes},
                    {"memory_load_cycles_total", load_cycles},
                    {"gpp_refit_cycles_total", refit_cycles},
                    {"wall_s", wall},
                    {"rays", rays},
                    {"rays_per_wall_s", wall > 0 ? rays / wall : 0}};
  doc["frames"] = frames;
  const auto dir = std::filesystem::path(dir_);
  write_atomically((dir / "stats.json").string(), [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << doc.dump(1) << "\n";
    out.close();  // a failed flush (disk full) must not be renamed into place
    if (!out) throw std::runtime_error("cannot write " + tmp);
  });
  write_atomically((dir / "stats.csv").string(), [&](const std::string& tmp) {
    std::ofstream out(tmp);
    // box (--accel bvh) and node (--top bvh) last, so that existing column positions stay.
    out << "frame,iu,spheres,primitives,rays,sphere,transform,primitive,idle,stall,busy,makespan,parallel_efficiency,"
           "box,node\n";
    for (const FrameStats& x : frames_)
      for (const UnitFrameStats& u : x.units)
        out << x.frame << ',' << u.id << ',' << u.spheres.size() << ',' << u.primitives << ',' << u.rays << ','
            << u.cycles.sphere << ',' << u.cycles.transform << ',' << u.cycles.primitive << ',' << u.idle << ','
            << u.cycles.stall << ',' << u.cycles.busy() << ',' << x.makespan << ',' << x.efficiency() << ','
            << u.cycles.box << ',' << u.cycles.node << '\n';
    out.close();  // a failed flush (disk full) must not be renamed into place
    if (!out) throw std::runtime_error("cannot write " + tmp);
  });
}

}  // namespace oprt
