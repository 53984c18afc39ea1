#include "stats.h"

#include "ref/image.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace oprt {

std::uint64_t FrameStats::busy() const {
  std::uint64_t b = 0;
  for (const auto& u : units) b += u.busy_cycles();
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
// A pipelined unit's stages: per stage busy (issuing), stall (frozen by a full output
// queue; the sphere unit also without a free ray slot; the triangle unit waiting for
// object memory), starved (its input queue empty while the unit holds rays) and idle (the
// unit holds no ray); they add up to the makespan.
nlohmann::json stages_json(const hw::PipelineStats& p, const hw::PipelineConfig& c, std::uint64_t makespan) {
  nlohmann::json stages = nlohmann::json::object();
  const std::uint64_t idle = makespan > p.occupied ? makespan - p.occupied : 0;
  for (int s = 0; s < hw::kPipeStages; ++s) {
    const hw::StageCycles& st = p.stage[s];
    const std::uint64_t used = st.busy + st.full + st.memory;
    nlohmann::json j = {{"busy", st.busy},
                        {"stall_queue_full", st.full},
                        {"stall_queue_empty", p.occupied > used ? p.occupied - used : 0},
                        {"idle", idle},
                        {"ii", c.stage[s].ii},
                        {"latency", c.stage[s].latency}};
    if (s == static_cast<int>(hw::PipeStage::triangle)) j["stall_memory"] = st.memory;
    stages[hw::to_string(static_cast<hw::PipeStage>(s))] = j;
  }
  return {{"stages", stages},
          {"occupied_cycles", p.occupied},
          {"answer_wait_cycles", p.answer_wait},
          {"jobs", p.jobs},
          {"triangle_tests", p.triangles},
          {"queue_peak", {{"transform", p.peak_queue[0]}, {"triangle", p.peak_queue[1]}}},
          {"rays_in_flight_peak", p.peak_in_flight}};
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
                     {"busy_cycles", u.busy_cycles()},
                     {"memory_bytes_read", u.memory_bytes},
                     {"memory", {{"cache", u.cache},
                                 {"assigned_bytes", u.assigned_bytes},
                                 {"hits", u.memory.hits},
                                 {"misses", u.memory.misses},
                                 {"dram_bytes", u.memory.dram_bytes},
                                 {"stall_cycles", u.memory.stall}}},
                     {"memory_load_bytes", u.memory_load_bytes},
                     {"fifo", {{"pushes", u.fifo_pushes}, {"pops", u.fifo_pops}, {"peak", u.fifo_peak}}},
                     {"work", {{"primary", work_json(u.work[0])}, {"shadow", work_json(u.work[1])}}}});
    if (u.pipeline && f.pipeline) units.back()["pipeline"] = stages_json(*u.pipeline, *f.pipeline, f.makespan);
  }
  const double rays = static_cast<double>(f.rays[0] + f.rays[1]);
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(f.image_hash));
  nlohmann::json j = {{"frame", f.frame},
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
  j["frame_time_s"] = f.frame_time_s;
  if (f.energy) {
    j["energy_j"] = f.energy->to_json();
    if (!f.energy->notes.empty()) j["energy_notes"] = f.energy->notes;
  }
  return j;
}

void StatsWriter::set_area(const Cost& area) {
  doc_["area_mm2"] = area.to_json();
  if (!area.notes.empty()) doc_["area_notes"] = area.notes;
  area_total_ = area.total;
}

StatsWriter::StatsWriter(std::string dir, nlohmann::json header)
    : dir_(std::move(dir)),
      csv_tmp_(temporary_path((std::filesystem::path(dir_) / "stats.csv").string())),
      doc_(std::move(header)),
      json_((std::filesystem::path(dir_) / "stats.json").string()) {}

StatsWriter::~StatsWriter() {
  try {
    finish();  // the frames completed before an error: as after a stop
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oprt: %s\n", e.what());
  }
  csv_.close();
  std::remove(csv_tmp_.c_str());
}

void StatsWriter::add(const FrameStats& f) {
  if (!csv_.is_open()) {
    csv_.open(csv_tmp_, std::ios::binary | std::ios::trunc);
    // box (--accel bvh), node (--top bvh) and the frame's totals last, so that existing
    // column positions stay.
    csv_ << "frame,iu,spheres,primitives,rays,sphere,transform,primitive,idle,stall,busy,makespan,parallel_efficiency,"
            "box,node,frame_time_s,energy_j,area_mm2\n";
  }
  for (const UnitFrameStats& u : f.units) {
    csv_ << f.frame << ',' << u.id << ',' << u.spheres.size() << ',' << u.primitives << ',' << u.rays << ','
         << u.cycles.sphere << ',' << u.cycles.transform << ',' << u.cycles.primitive << ',' << u.idle << ','
         << u.cycles.stall << ',' << u.busy_cycles() << ',' << f.makespan << ',' << f.efficiency() << ','
         << u.cycles.box << ',' << u.cycles.node << ',' << f.frame_time_s << ',';
    if (f.energy) csv_ << f.energy->total;
    csv_ << ',';
    if (area_total_) csv_ << *area_total_;
    csv_ << '\n';
  }
  csv_.flush();
  if (!csv_) throw std::runtime_error("cannot write " + csv_tmp_);
  json_.add(to_json(f));
  ++frames_;
  if (f.energy) energy_ += f.energy->total;
  energy_known_ = f.energy.has_value();
  frame_time_ += f.frame_time_s;
  wall_ += f.wall_s;
  efficiency_ += f.efficiency();
  idle_ += f.idle_fraction();
  makespan_ += f.makespan;
  busy_ += f.busy();
  rays_ += f.rays[0] + f.rays[1];
  load_bytes_ += f.memory_load_bytes;
  load_cycles_ += f.memory_load_cycles;
  refit_cycles_ += f.refit_cycles;
}

void StatsWriter::finish() {
  if (finished_ || frames_ == 0) return;
  finished_ = true;
  nlohmann::json doc = doc_;
  doc["summary"] = {{"frames", frames_},
                    {"makespan_cycles_total", makespan_},
                    {"parallel_efficiency_mean", efficiency_ / frames_},
                    {"idle_fraction_mean", idle_ / frames_},
                    {"busy_cycles_total", busy_},
                    {"memory_load_bytes_total", load_bytes_},
                    {"memory_load_cycles_total", load_cycles_},
                    {"gpp_refit_cycles_total", refit_cycles_},
                    {"wall_s", wall_},
                    {"rays", rays_},
                    {"rays_per_wall_s", wall_ > 0 ? rays_ / wall_ : 0},
                    {"frame_time_s_total", frame_time_}};
  if (energy_known_) doc["summary"]["energy_j_total"] = energy_;
  json_.write(doc);
  csv_.close();  // a failed flush (disk full) must not be renamed into place
  if (!csv_) throw std::runtime_error("cannot write " + csv_tmp_);
  std::filesystem::rename(csv_tmp_, std::filesystem::path(dir_) / "stats.csv");
}

}  // namespace oprt
