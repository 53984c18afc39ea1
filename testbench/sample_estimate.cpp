#include "sample_estimate.h"

#include "sample/strata.h"
#include "sample_expand.h"
#include "timing/transfers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace oprt {

using sample::Strata;
using timing::SampleFrame;

SampleEstimator::SampleEstimator(const Arch& arch, std::shared_ptr<const PixelSample> sample, int fifo_depth_timed,
                                 const RunCost& cost)
    : arch_(arch), sample_(std::move(sample)), fifo_depth_timed_(fifo_depth_timed), cost_(cost) {}

namespace {

constexpr std::size_t kDraws = 2000;
constexpr std::uint64_t kFewRecords = 30;  // below this the normal approximation of a unit's error fails

Strata strata_of(const SampleFrame& f, const PixelSample& s) {
  return Strata(f.y.data(), f.figures(), s.block_sizes(), s.group_of(), s.groups());
}

// A timed figure expanded by the ratio to its proxy (a per-pixel figure): X = (X_s / P_s) HT(P).
struct Ratio {
  double sampled = 0, estimate = 0, sd = 0, ratio = 0;
  std::size_t figure = 0;
};
Ratio ratio_of(const Strata& st, std::size_t figure, double sampled) {
  Ratio r;
  r.figure = figure;
  r.sampled = sampled;
  const double p = st.sample_sum(figure);
  r.ratio = p > 0 ? sampled / p : 0;
  r.estimate = r.ratio * st.total(figure);
  r.sd = r.ratio * std::sqrt(std::max(0.0, st.variance(figure)));
  return r;
}

// What bounds the frame's body: each unit's used time, the shared bus's busy time, the GPP's work.
struct Resources {
  std::vector<std::string> name;
  std::vector<Ratio> r;
  std::vector<int> unit;  // the unit a resource is, or -1
};

std::uint64_t bus_fixed_cycles(const FrameStats& fs, const Arch& a) {
  std::uint64_t c = 0;
  for (const UnitFrameStats& u : fs.units) {
    c += timing::bus_occupancy(a, u.config_bytes);
    if (u.memory_load_bytes) c += timing::bus_occupancy(a, u.memory_load_bytes);
  }
  return std::min<std::uint64_t>(c, fs.bus_busy);
}

Resources resources(const FrameStats& fs, const SampleFrame& f, const Strata& st, const Arch& a) {
  Resources res;
  for (std::size_t u = 0; u < fs.units.size(); ++u) {
    const UnitFrameStats& s = fs.units[u];
    const double used = static_cast<double>(s.pipeline ? s.pipeline->occupied : s.cycles.busy() + s.cycles.stall);
    res.name.push_back("unit " + std::to_string(u));
    res.r.push_back(ratio_of(st, f.work(u), used));
    res.unit.push_back(static_cast<int>(u));
  }
  if (a.bus.model == BusModel::shared) {
    res.name.push_back("bus");
    res.r.push_back(ratio_of(st, f.extra(SampleFrame::bus_cycles), static_cast<double>(fs.bus_busy - bus_fixed_cycles(fs, a))));
    res.unit.push_back(-1);
  }
  const std::size_t g = f.extra(SampleFrame::gpp_cycles);
  if (st.sample_sum(g) > 0) {
    res.name.push_back("gpp");
    res.r.push_back(ratio_of(st, g, st.sample_sum(g)));
    res.unit.push_back(-1);
  }
  return res;
}

double component(const FrameStats& fs, const char* name) {
  if (!fs.energy) return 0;
  for (const auto& c : fs.energy->components)
    if (c.name == name && c.value) return *c.value;
  return 0;
}

// The sampled frame's dynamic energy as a linear function of the per-pixel figures: its
// arithmetic per unit of work, its object-memory and DRAM energy per byte read, its FIFO energy
// per ray written, its bus energy per byte (each the frame's own average price).
std::vector<double> energy_weights(const FrameStats& fs, const SampleFrame& f, const Strata& st) {
  std::vector<double> w(f.figures(), 0.0);
  if (!fs.energy) return w;
  double arithmetic = 0, work = 0, bytes = 0;
  for (const char* c : {"fp_add", "fp_multiply", "fp_compare", "fp_inverse", "box_tests", "node_tests", "register_file",
                        "pipeline_buffers", "traversal_stacks", "miss_registers", "router"})
    arithmetic += component(fs, c);
  for (std::size_t u = 0; u < f.units; ++u) work += st.sample_sum(f.work(u)), bytes += st.sample_sum(f.bytes(u));
  for (std::size_t u = 0; u < f.units; ++u) {
    if (work > 0) w[f.work(u)] = arithmetic / work;
    if (bytes > 0) w[f.bytes(u)] = (component(fs, "object_memory_reads") + component(fs, "dram")) / bytes;
  }
  const auto per_figure = [&](SampleFrame::Extra e, const char* c) {
    const double s = st.sample_sum(f.extra(e));
    if (s > 0) w[f.extra(e)] = component(fs, c) / s;
  };
  per_figure(SampleFrame::unit_writes, "ray_fifo");
  per_figure(SampleFrame::bus_bytes, "bus");
  return w;
}

// The frame's body: eta times the largest resource's demand, that maximum's bias and spread
// drawn jointly with the dynamic energy (weights w over the per-pixel figures).
struct Body {
  double start = 0, eta = 1;
  std::vector<std::size_t> candidates;  // resources that may be the largest
  std::size_t bottleneck = 0;
  sample::MaxEstimate max;
  std::vector<double> max_draws, energy_draws;  // per draw: the largest resource; the dynamic energy's deviation
};

Body body(const Resources& res, const Strata& st, const std::vector<double>& w, double start, double makespan,
          std::uint64_t seed) {
  Body b;
  b.start = start;
  double largest = 0, largest_sampled = 0;
  for (std::size_t k = 0; k < res.r.size(); ++k) {
    if (res.r[k].estimate > largest) largest = res.r[k].estimate, b.bottleneck = k;
    largest_sampled = std::max(largest_sampled, res.r[k].sampled);
  }
  if (largest_sampled > 0) b.eta = (makespan - start) / largest_sampled;
  for (std::size_t k = 0; k < res.r.size(); ++k)
    if (res.r[k].estimate + 6 * res.r[k].sd >= largest) b.candidates.push_back(k);
  std::vector<std::size_t> figs;
  for (std::size_t k : b.candidates) figs.push_back(res.r[k].figure);
  const std::size_t m = figs.size();
  std::vector<double> cov(m * m), mean(m + 1), joint((m + 1) * (m + 1), 0.0);
  const std::vector<double> c = st.covariance(figs), e = st.covariance_with(w, figs);
  for (std::size_t a = 0; a < m; ++a) {
    const double ra = res.r[b.candidates[a]].ratio;
    mean[a] = res.r[b.candidates[a]].estimate;
    for (std::size_t k = 0; k < m; ++k) joint[a * (m + 1) + k] = c[a * m + k] * ra * res.r[b.candidates[k]].ratio;
    joint[a * (m + 1) + m] = joint[m * (m + 1) + a] = e[a] * ra;
  }
  joint[m * (m + 1) + m] = e[m];
  mean[m] = 0;  // the energy's deviation
  for (const auto& d : sample::normal_draws(mean, joint, kDraws, seed)) {
    b.max_draws.push_back(m ? *std::max_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(m)) : 0.0);
    b.energy_draws.push_back(d[m]);
  }
  b.max = sample::max_from_draws(b.max_draws, largest, b.bottleneck);
  return b;
}

// Under queueing (eta > 1) the body is not one resource's demand, and its error is not that
// maximum's alone: the pace of the frame follows, pixel by pixel, whichever resource is the
// slowest on its rays. The body's relative error as that per-pixel pace's (a ratio estimate)
// bounds it from the other side; the interval takes the wider of the two.
double pace_sd(const SampleFrame& f, const Strata& st, double body) {
  std::vector<double> pace(st.pixels());
  for (std::size_t i = 0; i < st.pixels(); ++i) {
    double q = std::max(st.at(i, f.extra(SampleFrame::bus_cycles)), st.at(i, f.extra(SampleFrame::gpp_cycles)));
    for (std::size_t u = 0; u < f.units; ++u) q = std::max(q, st.at(i, f.work(u)));
    pace[i] = q;
  }
  const double total = st.series_total(pace);
  return total > 0 ? body * std::sqrt(std::max(0.0, st.series_variance(pace))) / total : 0.0;
}

// A normal interval at 95 %.
nlohmann::json normal_interval(double estimate, double sd) {
  return nlohmann::json::array({estimate - sample::kZ95 * sd, estimate + sample::kZ95 * sd});
}

// A sum of per-pixel figures, sum_k w_k HT(figure k), and its standard error.
std::pair<double, double> linear(const Strata& st, const std::vector<double>& w) {
  double total = 0;
  for (std::size_t k = 0; k < w.size(); ++k)
    if (w[k] != 0) total += w[k] * st.total(k);
  const std::vector<double> v = st.covariance_with(w, {});
  return {total, std::sqrt(std::max(0.0, v.back()))};
}

}  // namespace

namespace {

// The energy: the cost model on the expanded frame; its interval from the dynamic energy's
// draws and the leakage over each draw's makespan, reflected about the estimate (basic bootstrap).
void energy_estimate(RunCost& cost, const Arch& a, SampleEstimate& out, const FrameStats& x, const Body& b,
                     nlohmann::json& estimate, nlohmann::json& interval) {
  const Cost c = cost.frame(x);
  out.energy = c.total;
  double leakage = 0;
  for (const auto& k : c.components)
    if (k.name == "leakage" && k.value) leakage = *k.value;
  const double per_cycle = x.makespan ? leakage / static_cast<double>(x.makespan) : 0;
  double mean = 0;
  for (double m : b.max_draws) mean += m;
  mean /= static_cast<double>(std::max<std::size_t>(1, b.max_draws.size()));
  std::vector<double> d(b.max_draws.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = b.energy_draws[i] + per_cycle * b.eta * (b.max_draws[i] - mean);
  const double hi = sample::quantile(d, (1 + sample::kConfidence) / 2), lo = sample::quantile(d, (1 - sample::kConfidence) / 2);
  out.energy_interval = {c.total - hi, c.total - lo};
  estimate["energy_j"] = c.total;
  interval["energy_j"] = out.energy_interval;
  if (a.fifo_depth == 0) estimate["area_mm2"] = cost.area().total;  // FIFOs sized by their peak: a design estimate
}

// What adds up over the rays: busy cycles (per unit and in all), rays, bytes read from object
// memory and from DRAM, bus bytes and busy cycles; each with a normal interval.
void additive_estimates(const FrameStats& fs, const SampleFrame& f, const Strata& st, const Resources& res,
                        const Arch& a, nlohmann::json& estimate, nlohmann::json& interval) {
  const std::size_t n = f.figures();
  std::vector<double> busy_w(n, 0.0), bytes_w(n, 0.0), dram_w(n, 0.0), rays_w(n, 0.0), bus_w(n, 0.0);
  nlohmann::json per_unit = nlohmann::json::array(), per_unit_interval = nlohmann::json::array();
  for (std::size_t u = 0; u < f.units; ++u) {
    const UnitFrameStats& s = fs.units[u];
    const Ratio r = ratio_of(st, f.work(u), static_cast<double>(s.busy_cycles()));
    per_unit.push_back(r.estimate);
    per_unit_interval.push_back(normal_interval(r.estimate, r.sd));
    busy_w[f.work(u)] = r.ratio;
    bytes_w[f.bytes(u)] = 1;
    const double read = st.sample_sum(f.bytes(u));
    if (read > 0) dram_w[f.bytes(u)] = static_cast<double>(s.memory.dram_bytes) / read;
  }
  rays_w[f.extra(SampleFrame::rays)] = 1;
  bus_w[f.extra(SampleFrame::bus_bytes)] = 1;
  const auto put = [&](const char* key, std::pair<double, double> v, double fixed = 0) {
    estimate[key] = fixed + v.first;
    interval[key] = normal_interval(fixed + v.first, v.second);
  };
  put("busy_cycles", linear(st, busy_w));
  estimate["busy_cycles_per_unit"] = per_unit;
  interval["busy_cycles_per_unit"] = per_unit_interval;
  put("rays", linear(st, rays_w));
  put("memory_bytes_read", linear(st, bytes_w));
  put("dram_bytes", linear(st, dram_w));
  // The bus: the registers written and the geometry loaded once, the rays' traffic expanded.
  put("bus_bytes", linear(st, bus_w), static_cast<double>(fs.bus_bytes) - st.sample_sum(f.extra(SampleFrame::bus_bytes)));
  double bus_busy = static_cast<double>(fs.bus_busy), bus_sd = 0;
  for (std::size_t k = 0; k < res.name.size(); ++k)
    if (res.name[k] == "bus") bus_busy = static_cast<double>(bus_fixed_cycles(fs, a)) + res.r[k].estimate, bus_sd = res.r[k].sd;
  put("bus_busy_cycles", {bus_busy, bus_sd});
}

// The frame's "sample" object but its estimates: what was sampled and how the body was read.
nlohmann::json sample_header(const PixelSample& s, double expansion, int fifo_timed, const FrameStats& fs,
                             const Resources& res, const Body& b) {
  nlohmann::json j = {{"fraction", 1.0 / s.n()},
                      {"fraction_text", s.fraction_text()},
                      {"seed", s.seed()},
                      {"block", {s.block_width(), s.block_height()}},
                      {"pixels", s.size()},
                      {"frame_pixels", s.frame_pixels()},
                      {"expansion", expansion},
                      {"confidence", sample::kConfidence},
                      {"start_cycles", fs.start_cycles},
                      {"eta", b.eta},
                      {"max_bias_cycles", b.eta * b.max.bias}};
  if (fifo_timed > 0) j["fifo_depth_timed"] = fifo_timed;
  if (!res.name.empty()) j["bottleneck"] = res.name[b.bottleneck];
  nlohmann::json candidates = nlohmann::json::array();
  for (std::size_t k : b.candidates) candidates.push_back(res.name[k]);
  j["candidates"] = candidates;
  return j;
}

}  // namespace

namespace {

// Why an interval is not to be trusted, and what a flag means (docs/timing-levels.md).
const char* flag_text(const std::string& flag) {
  if (flag == "few_rays") return "a busiest unit's estimate rests on fewer than 30 sampled rays that entered its spheres";
  if (flag == "ordering")
    return "the frame is set by queueing (bounded ray FIFOs or a shared bus), which depends on the order of the rays: "
           "the sample's rays are a block apart, less alike than the frame's neighbours";
  if (flag == "pipelined")
    return "pipelined units overlap the rays they hold, and the sample's rays in flight together are less alike than "
           "the frame's";
  if (flag == "cache") return "caches see the sample's rays, a block apart: they miss more often than in the full frame";
  if (flag == "feedback_sampled") return "the feedback policy balanced this frame on the frame before's sampled costs";
  return "";
}

// The flags of a frame: those that make its interval untrustworthy first (trusted: none).
std::vector<std::string> flags_of(const FrameStats& fs, const timing::SampleFrame& f, const Resources& res,
                                  const Body& b, const Arch& a, bool feedback, std::size_t pixels) {
  std::vector<std::string> flags;
  bool few = pixels < kFewRecords;
  double largest = 0;
  for (const Ratio& r : res.r) largest = std::max(largest, r.estimate);
  for (std::size_t k : b.candidates)  // those within two standard errors of the largest
    if (res.unit[k] >= 0 && res.r[k].sd > 0 && res.r[k].estimate + 2 * res.r[k].sd >= largest &&
        f.records[static_cast<std::size_t>(res.unit[k])] < kFewRecords)
      few = true;
  if (few) flags.push_back("few_rays");
  if ((a.fifo_depth > 0 || a.bus.model == BusModel::shared) && b.eta > 1.05) flags.push_back("ordering");
  if (a.iu.model == IuModel::pipelined) flags.push_back("pipelined");
  if (std::any_of(fs.units.begin(), fs.units.end(), [](const UnitFrameStats& u) { return u.cache; }))
    flags.push_back("cache");
  if (feedback) flags.push_back("feedback_sampled");
  return flags;
}

}  // namespace

void SampleEstimator::warn(const std::vector<std::string>& flags) {
  for (const std::string& flag : flags) {
    const char* text = flag_text(flag);
    if (!*text || !warned_.insert(flag).second) continue;
    std::fprintf(stderr, "oprt: warning: --sample %s: %s; the interval covers the sampling error only (%s)\n",
                 sample_->fraction_text().c_str(), text, flag.c_str());
  }
}

SampleEstimate SampleEstimator::estimate(const timing::FrameRun& run, const FrameStats& fs) {
  const SampleFrame& f = *run.sample;
  const Strata st = strata_of(f, *sample_);
  const std::size_t rays = f.extra(SampleFrame::rays);
  expansion_ = st.sample_sum(rays) > 0 ? st.total(rays) / st.sample_sum(rays) : static_cast<double>(sample_->n());
  const Resources res = resources(fs, f, st, arch_);
  const std::vector<double> w = energy_weights(fs, f, st);
  const double start = static_cast<double>(fs.start_cycles), sampled = static_cast<double>(fs.makespan);
  const Body b = body(res, st, w, start, sampled, sample_->seed() * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(frames_));
  SampleEstimate out;
  out.makespan = start + b.eta * b.max.estimate();
  out.makespan_interval = {start + b.eta * b.max.low, start + b.eta * b.max.high};
  if (b.eta > 1.05) {  // queueing: the wider of the two errors (pace_sd)
    const double body = out.makespan - start, half = sample::kZ95 * pace_sd(f, st, body);
    out.makespan_interval = {std::min(out.makespan_interval[0], out.makespan - half),
                             std::max(out.makespan_interval[1], out.makespan + half)};
  }
  if (b.max.plain <= 0) {  // nothing but the start: the body compressed as it is
    out.makespan = start + expansion_ * (sampled - start);
    out.makespan_interval = {out.makespan, out.makespan};
  }
  const double cycle_s = arch_.cycle_ns() * 1e-9;
  out.frame_time_s = out.makespan * cycle_s;
  out.frame_time_interval = {out.makespan_interval[0] * cycle_s, out.makespan_interval[1] * cycle_s};
  const FrameStats x = expand_frame(fs, expansion_, static_cast<std::uint64_t>(std::llround(out.makespan)),
                                    out.frame_time_s, arch_.fifo_depth == 0);
  nlohmann::json estimate, interval;
  if (fs.energy) energy_estimate(cost_, arch_, out, x, b, estimate, interval);
  additive_estimates(fs, f, st, res, arch_, estimate, interval);
  out.flags = flags_of(fs, f, res, b, arch_, arch_.balance == "feedback" && frames_ > 0, sample_->size());
  out.trusted = out.flags.empty();
  warn(out.flags);
  if (fs.start_cycles * 2 > out.makespan) out.flags.push_back("fixed_work");
  if (std::fabs(b.eta * b.max.bias) * 4 > out.makespan_interval[1] - out.makespan_interval[0]) out.flags.push_back("max_bias");
  if (fifo_depth_timed_ != arch_.fifo_depth) out.flags.push_back("fifos_scaled");
  if (arch_.fifo_depth == 0 && fs.energy) out.flags.push_back("fifo_size_estimated");
  estimate["makespan_cycles"] = out.makespan;
  interval["makespan_cycles"] = out.makespan_interval;
  estimate["frame_time_s"] = out.frame_time_s;
  interval["frame_time_s"] = out.frame_time_interval;
  out.json = sample_header(*sample_, expansion_, fifo_depth_timed_, fs, res, b);
  out.json["estimate"] = estimate;
  out.json["interval"] = interval;
  out.json["trusted"] = out.trusted;
  out.json["flags"] = out.flags;
  ++frames_;
  return out;
}

}  // namespace oprt
