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

double FrameStats::fanout_mean() const {
  std::uint64_t rays = 0, pairs = 0;
  for (std::size_t k = 0; k < route.fanout.size(); ++k) rays += route.fanout[k], pairs += k * route.fanout[k];
  return rays ? static_cast<double>(pairs) / static_cast<double>(rays) : 0;
}

std::uint64_t FrameStats::fanout_max() const {
  for (std::size_t k = route.fanout.size(); k-- > 0;)
    if (route.fanout[k]) return k;
  return 0;
}

double FrameStats::efficiency() const {
  return makespan && !units.empty() ? static_cast<double>(busy()) / (static_cast<double>(units.size()) * makespan) : 0;
}

double FrameStats::idle_fraction() const {
  std::uint64_t idle = 0;
  for (const auto& u : units) idle += u.idle;
  return makespan && !units.empty() ? static_cast<double>(idle) / (static_cast<double>(units.size()) * makespan) : 0;
}

// The work counters as stats.json and reference.json write them (one place for both).
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

namespace {
// A pipelined unit: per unit in use its operations, busy (issuing: ops x II), starved (the IU
// holds rays but none has an operation for it) and idle (the IU holds no ray), which add up
// to the makespan; then the rays' waits (for a free slot, for object memory, for the bus)
// and the traversal stack.
nlohmann::json stages_json(const timing::PipelineStats& p, const timing::PipelineConfig& c, std::uint64_t makespan) {
  nlohmann::json stages = nlohmann::json::object();
  const std::uint64_t idle = makespan > p.occupied ? makespan - p.occupied : 0;
  for (int s = 0; s < timing::kPipeStages; ++s) {
    if (!c.stage[s].used) continue;
    const timing::StageCycles& st = p.stage[s];
    stages[timing::to_string(static_cast<timing::PipeStage>(s))] = {{"ops", st.ops},
                                                            {"busy", st.busy},
                                                            {"starved", p.occupied > st.busy ? p.occupied - st.busy : 0},
                                                            {"idle", idle},
                                                            {"ii", c.stage[s].ii},
                                                            {"latency", c.stage[s].latency}};
  }
  return {{"stages", stages},
          {"occupied_cycles", p.occupied},
          {"slot_wait_cycles", p.slot_wait},
          {"memory_wait_cycles", p.memory_wait},
          {"answer_wait_cycles", p.answer_wait},
          {"jobs", p.jobs},
          {"stack", {{"pushes", p.stack_pushes}, {"spills", p.stack_spills}, {"fills", p.stack_fills}}},
          {"rays_in_flight_peak", p.peak_in_flight}};
}
}  // namespace

namespace {
// Per ray kind: primary and shadow always, the secondary kinds when the frame has any (so
// that a frame without them reads as it did before they existed).
template <typename F>
nlohmann::json per_kind(const FrameStats& f, F&& value) {
  nlohmann::json j;
  for (int k = 0; k < kRayKinds; ++k)
    if (k < 2 || f.rays[k]) j[kRayKindNames[k]] = value(k);
  return j;
}

// What each kind of ray asked of the engine (timing/ray_figures.h), per ray, and the rays
// per depth.
nlohmann::json ray_kinds_json(const FrameStats& f) {
  const timing::RayFigures& r = f.ray_figures;
  const auto per = [](std::uint64_t x, std::uint64_t n) { return n ? static_cast<double>(x) / n : 0.0; };
  nlohmann::json j = per_kind(f, [&](int k) {
    const timing::KindFigures& kf = r.kind[k];
    return nlohmann::json{{"rays", kf.rays},
                          {"fanout_mean", per(kf.unit_writes, kf.rays)},
                          {"ray_bytes_per_ray", per(kf.ray_bytes, kf.rays)},
                          {"answer_bytes_per_ray", per(kf.answer_bytes, kf.rays)},
                          {"latency_cycles_mean", per(kf.latency, kf.rays)},
                          {"spawn_delay_cycles_mean", per(kf.spawn_delay, kf.rays)}};
  });
  nlohmann::json depths = nlohmann::json::array();
  for (std::size_t d = 0; d < r.by_depth.size(); ++d) {
    nlohmann::json row = {{"depth", d}};
    for (int k = 0; k < kRayKinds; ++k)
      if (k < 2 || f.rays[k]) row[kRayKindNames[k]] = r.by_depth[d][k];
    depths.push_back(row);
  }
  return {{"kinds", j}, {"by_depth", depths}, {"gpp_starved_cycles", r.starved}};
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
                     {"work", per_kind(f, [&](int k) { return work_json(u.work[k]); })}});
    if (u.pipeline && f.pipeline) units.back()["pipeline"] = stages_json(*u.pipeline, *f.pipeline, f.makespan);
  }
  const double rays = static_cast<double>(f.total_rays());
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(f.image_hash));
  nlohmann::json j = {{"frame", f.frame},
          {"makespan_cycles", f.makespan},
          {"parallel_efficiency", f.efficiency()},
          {"idle_fraction", f.idle_fraction()},
          {"busy_cycles", f.busy()},
          {"wall_s", f.wall_s},
          {"rays", per_kind(f, [&](int k) { return f.rays[k]; })},
          {"rays_per_wall_s", f.wall_s > 0 ? rays / f.wall_s : 0},
          {"bus", {{"busy_cycles", f.bus_busy}, {"bytes", f.bus_bytes}, {"transfers", f.bus_transfers}}},
          {"memory_load_bytes", f.memory_load_bytes},
          {"memory_load_cycles", f.memory_load_cycles},
          {"gpp", {{"refit_nodes", f.refit_nodes}, {"refit_cycles", f.refit_cycles}, {"nodes_built", f.built_nodes}}},
          {"route", {{"fanout_mean", f.fanout_mean()},
                     {"fanout_max", f.fanout_max()},
                     {"fanout_histogram", f.route.fanout},
                     {"cycles", f.route.cycles},
                     {"skipped", f.route.skipped},
                     {"bounds", f.route.bounds}}},
          {"bus_bytes_per_ray", rays > 0 ? static_cast<double>(f.bus_bytes) / rays : 0},
          {"image_hash", hash},
          {"sphere_cycles", f.sphere_cycles},
          {"sphere_entries", f.sphere_entries},
          {"ius", units}};
  j["frame_time_s"] = f.frame_time_s;
  j["ray_kinds"] = ray_kinds_json(f);
  if (f.replicating) {
    nlohmann::json copies = nlohmann::json::array();
    for (const Replica& r : f.replicas) copies.push_back({{"sphere", r.sphere}, {"units", r.units}});
    j["replicas"] = {{"copies", copies}, {"bytes", f.replica_bytes}, {"geometry_bytes", f.geometry_bytes}};
  }
  if (f.sample) j["sample"] = f.sample->json;
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
            "box,node,frame_time_s,energy_j,area_mm2,fanout_mean,fanout_max,fanout_histogram,route_cycles,route_skipped,"
            "bus_bytes_per_ray";
    // --sample: the row's figures are the sample's; the estimates of the full frame follow.
    if (f.sample) csv_ << ",est_busy,est_makespan,est_frame_time_s,est_energy_j";
    csv_ << "\n";
  }
  const std::uint64_t rays = f.total_rays();
  for (const UnitFrameStats& u : f.units) {
    csv_ << f.frame << ',' << u.id << ',' << u.spheres.size() << ',' << u.primitives << ',' << u.rays << ','
         << u.cycles.sphere << ',' << u.cycles.transform << ',' << u.cycles.primitive << ',' << u.idle << ','
         << u.cycles.stall << ',' << u.busy_cycles() << ',' << f.makespan << ',' << f.efficiency() << ','
         << u.cycles.box << ',' << u.cycles.node << ',' << f.frame_time_s << ',';
    if (f.energy) csv_ << f.energy->total;
    csv_ << ',';
    if (area_total_) csv_ << *area_total_;
    csv_ << ',' << f.fanout_mean() << ',' << f.fanout_max() << ',';
    for (std::size_t k = 0; k < f.route.fanout.size(); ++k) csv_ << (k ? " " : "") << f.route.fanout[k];
    csv_ << ',' << f.route.cycles << ',' << f.route.skipped << ','
         << (rays ? static_cast<double>(f.bus_bytes) / static_cast<double>(rays) : 0.0);
    if (f.sample) {
      csv_ << ',' << f.sample->json["estimate"]["busy_cycles_per_unit"].at(static_cast<std::size_t>(u.id)).get<double>()
           << ',' << f.sample->makespan << ',' << f.sample->frame_time_s << ',';
      if (f.sample->energy) csv_ << *f.sample->energy;
    }
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
  rays_ += f.total_rays();
  load_bytes_ += f.memory_load_bytes;
  load_cycles_ += f.memory_load_cycles;
  refit_cycles_ += f.refit_cycles;
  if (f.sample) add_sample(*f.sample);
}

// The run's estimates: the frames' sums, their intervals the sums of the frames' bounds (the
// frames share their pixels, so their errors are not independent: this bound is safe).
void StatsWriter::add_sample(const SampleEstimate& e) {
  nlohmann::json& s = sample_;
  if (s.is_null()) {
    s = {{"fraction", e.json["fraction"]}, {"fraction_text", e.json["fraction_text"]}, {"seed", e.json["seed"]},
         {"confidence", e.json["confidence"]}, {"trusted", true}};
    s["estimate"] = {{"makespan_cycles_total", 0.0}, {"frame_time_s_total", 0.0}};
    s["interval"] = {{"makespan_cycles_total", {0.0, 0.0}}, {"frame_time_s_total", {0.0, 0.0}}};
    if (e.energy) s["estimate"]["energy_j_total"] = 0.0, s["interval"]["energy_j_total"] = {0.0, 0.0};
  }
  const auto add = [&](const char* key, double v, const std::array<double, 2>& i) {
    s["estimate"][key] = s["estimate"][key].get<double>() + v;
    s["interval"][key] = {s["interval"][key][0].get<double>() + i[0], s["interval"][key][1].get<double>() + i[1]};
  };
  add("makespan_cycles_total", e.makespan, e.makespan_interval);
  add("frame_time_s_total", e.frame_time_s, e.frame_time_interval);
  if (e.energy && s["estimate"].contains("energy_j_total")) add("energy_j_total", *e.energy, e.energy_interval);
  s["trusted"] = s["trusted"].get<bool>() && e.trusted;
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
  if (!sample_.is_null()) doc["summary"]["sample"] = sample_;
  json_.write(doc);
  csv_.close();  // a failed flush (disk full) must not be renamed into place
  if (!csv_) throw std::runtime_error("cannot write " + csv_tmp_);
  std::filesystem::rename(csv_tmp_, std::filesystem::path(dir_) / "stats.csv");
}

}  // namespace oprt
