#include "render.h"

#include "balance/policy.h"
#include "cost/tech.h"
#include "timing/pipeline_timing.h"
#include "ref/parallel.h"
#include "ref/scene_geometry.h"
#include "base/error.h"
#include "scene/load.h"
#include "memory_estimate.h"
#include "outputs.h"
#include "ref/balance_inputs.h"
#include "base/numbers.h"
#include "testbench.h"
#include "hw/local_clock.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>
#include <unistd.h>

#include <systemc>

namespace oprt {

extern std::function<int()> g_simulation;

Arch resolve_arch(const RenderOptions& o) {
  Arch a = o.arch_file.empty() ? Arch{} : load_arch(o.arch_file);
  if (o.ius) a.ius = *o.ius;
  if (o.level) a.level = *o.level == "at" ? Level::at : *o.level == "lt" ? Level::lt : Level::analytic;
  if (o.quantum) a.quantum_ns = static_cast<double>(parse_time_ps(*o.quantum, false, {"--quantum", *o.quantum})) / 1000;
  if (o.balance) a.balance = *o.balance;
  if (o.locality) a.locality = parse_locality(*o.locality);
  if (o.replicate) a.replicate = replicate_named(*o.replicate, "--replicate");
  if (o.subdivide) a.subdivide = *o.subdivide;
  if (o.depth) a.gpp.depth = *o.depth;
  if (!o.split.empty()) a.split = o.split;
  if (o.accel) a.accel = *o.accel;
  if (o.top) a.top = *o.top;
  if (o.route) a.route.policy = *o.route;
  if (o.sram) {
    a.memory.sram_bytes = parse_bytes(*o.sram, kMaxSramBytes, {"--sram", *o.sram});
    check_sram(a, "--sram", *o.sram);
  }
  if (o.kernel) {
    const auto k = kernel_named(*o.kernel);
    if (!k) throw InputError("--kernel", *o.kernel, "unknown kernel (expected moller or watertight)");
    a.kernel = *k;
  }
  if (o.precision) a.precision = *o.precision;
  if (o.iu) a.iu.model = *o.iu == "pipelined" ? IuModel::pipelined : IuModel::serial;
  // Where a setting that check_arch refuses came from: the flag, or the file that set it
  // (a value other than the default's; the defaults themselves are never refused).
  const auto origin = [&](const std::string& key) -> std::string {
    const std::string file = a.source + ": ";
    if (key == "iu.model") return o.iu ? "--iu " + *o.iu : file + "/iu/model " + to_string(a.iu.model);
    if (key == "accel") return o.accel ? "--accel " + *o.accel : file + "/accel " + a.accel;
    if (key == "top") return o.top ? "--top " + *o.top : file + "/top " + a.top;
    if (key == "balance") return o.balance ? "--balance " + *o.balance : file + "/balance " + a.balance;
    if (key == "balance.locality") {
      if (o.locality) return "--locality " + *o.locality;
      std::ostringstream f;
      f << *a.locality;
      return file + "/balance/locality " + f.str();
    }
    if (key == "memory.sram_bytes")
      return o.sram ? "--sram " + *o.sram : file + "/memory/sram_bytes " + std::to_string(a.memory.sram_bytes);
    return file + key;
  };
  check_arch(a, origin);
  return a;
}

namespace {

// --trace-*: only with something to trace.
TraceSelection trace_selection(const RenderOptions& o, const FrameRange& rendered) {
  TraceSelection t;
  const std::pair<const char*, const std::optional<std::string>*> options[] = {{"--trace-frames", &o.trace_frames},
                                                                              {"--trace-window", &o.trace_window},
                                                                              {"--trace-units", &o.trace_units},
                                                                              {"--trace-signals", &o.trace_signals}};
  for (const auto& [option, value] : options)
    if (*value && o.vcd.empty() && o.timeline.empty())
      throw InputError(option, **value, "selects what --vcd or --timeline traces, and neither is given");
  if (o.trace_frames) t.frames = parse_trace_frames(*o.trace_frames, rendered);
  if (o.trace_window) parse_trace_window(*o.trace_window, t.from_ps, t.to_ps);
  if (o.trace_units) t.units = parse_trace_units(*o.trace_units);
  if (o.trace_signals) t.groups = parse_trace_signals(*o.trace_signals);
  return t;
}

// An exception out of a SystemC process arrives as SystemC's report "uncaught exception"
// (E549) wrapping its text: the original error again, an InputError when it was one, and a
// simulated time that would not fit reworded with the settings that make it so long.
std::exception_ptr from_process(std::exception_ptr failure, const RenderJob& job) {
  try {
    try {
      std::rethrow_exception(failure);
    } catch (const sc_core::sc_report& r) {
      if (std::string(r.get_msg_type()) != sc_core::SC_ID_SIMULATION_UNCAUGHT_EXCEPTION_) throw;
      if (auto e = InputError::thrown_with_text(r.get_msg())) throw *e;
      throw std::runtime_error(r.get_msg());
    }
  } catch (const InputError& e) {
    if (e.file() != hw::kSimulatedTime) return std::current_exception();
    const Arch& a = job.arch;
    std::ostringstream clock;
    clock << a.clock_mhz << " MHz";
    return std::make_exception_ptr(InputError(
        a.source, "/clock_mhz and /costs",
        "in frame " + std::to_string(job.frames.first + job.completed) + " (" + e.place() + "), " + e.problem() +
            ": at " + clock.str() + " a cycle is " + format_time_ps(static_cast<std::uint64_t>(a.cycle_ns() * 1000)) +
            "; raise clock_mhz, lower the costs, render fewer frames in one run, or use --level analytic (cycles "
            "without a time limit)"));
  } catch (...) {
    return std::current_exception();
  }
}

}  // namespace

struct RenderCache {
  std::map<std::string, std::shared_ptr<const Scene>> scenes;  // by file and load options
  template <typename T>
  struct Built {
    std::vector<SphereDef> spheres;
    SceneGeometry<T> geometry;
  };
  std::map<std::string, std::shared_ptr<const Built<float>>> float_geometry;  // by scene and geometry options
  std::map<std::string, std::shared_ptr<const Built<double>>> double_geometry;
  std::string scene_key;  // the current render's scene
  auto& geometry(float*) { return float_geometry; }
  auto& geometry(double*) { return double_geometry; }
};

std::shared_ptr<RenderCache> make_render_cache() { return std::make_shared<RenderCache>(); }

namespace {

// The scene, loaded or from the cache.
std::shared_ptr<const Scene> shared_scene(const std::string& file, const LoadOptions& load, RenderCache* cache) {
  if (!cache) return std::make_shared<const Scene>(load_scene(file, load));
  std::ostringstream key;
  key << file << '|' << load.aff.max_object_triangles << '|' << load.aff.sphere_segments << '|' << load.aff.sphere_rings
      << '|' << load.aff.cone_segments;
  cache->scene_key = key.str();
  auto& slot = cache->scenes[cache->scene_key];
  if (!slot) slot = std::make_shared<const Scene>(load_scene(file, load));
  return slot;
}

// The spheres and their geometry, built or from the cache.
template <typename T>
std::shared_ptr<const RenderCache::Built<T>> shared_geometry(const RenderOptions& o, const Scene& scene, const Arch& a,
                                                             RenderCache* cache) {
  const auto build = [&] {
    auto spheres = make_spheres(scene, a.subdivide, split_rule_named(a.split_rule), object_split_named(a.split, o.scene));
    SceneGeometry<T> geometry = build_geometry<T>(scene, spheres, a.kernel, accel_named(a.accel));
    return std::make_shared<const RenderCache::Built<T>>(RenderCache::Built<T>{std::move(spheres), std::move(geometry)});
  };
  if (!cache) return build();
  std::ostringstream key;
  key << cache->scene_key << '|' << a.subdivide << '|' << a.split_rule << '|' << a.split << '|'
      << static_cast<int>(a.kernel) << '|' << a.accel;
  auto& slot = cache->geometry(static_cast<T*>(nullptr))[key.str()];
  if (!slot) slot = build();
  return slot;
}

// What run_render checked before loading, for the checks that need the scene.
struct Prepared {
  OutputPlan outputs;
  MemoryLimit limit;
  RunShape shape;
};

template <typename T>
int render(const RenderOptions& o, const Scene& scene, RenderJob& job, Prepared& p, RenderCache* cache) {
  const auto built = shared_geometry<T>(o, scene, job.arch, cache);
  const std::vector<SphereDef>& spheres = built->spheres;
  const std::size_t units = units_for(spheres.size(), static_cast<std::size_t>(job.arch.ius));
  // The whole run, now that the scene, its image and its units are known, before the engine
  // and the frames allocate anything.
  p.shape.units = units;
  std::uint64_t vertices = 0;
  for (const Object& obj : scene.objects) vertices += obj.mesh.vertices.size();
  const bool own_resolution = o.resolution.empty();
  MemoryEstimate need = memory_estimate(
      p.shape, std::uint64_t(job.width) * std::uint64_t(job.height), rays_per_pixel(scene, job.arch.gpp.depth),
      own_resolution ? NumberSource{o.scene, "its image, " + std::to_string(job.width) + "x" + std::to_string(job.height)}
                     : NumberSource{"--resolution", o.resolution});
  add_geometry(need, p.shape, vertices, scene.triangle_count(), o.scene);
  refuse_if_over(need, p.limit);
  if (o.check) {
    std::printf("oprt: --check: %s: the run would need %s; it may use %s (%s); nothing rendered\n", o.scene.c_str(),
                last_memory_estimate().c_str(), byte_count_text(p.limit.bytes).c_str(), p.limit.source.c_str());
    return 0;
  }
  p.outputs.create_folders();
  if (units < static_cast<std::size_t>(job.arch.ius))
    std::printf("oprt: %d intersection units requested, the scene has %zu spheres: instantiating %zu units\n",
                job.arch.ius, spheres.size(), units);
  SceneGeometry<T> geometry = built->geometry;  // a copy: a deforming scene changes it frame by frame
  const SaNCosts costs = sa_n_costs(job.arch, geometry);
  job.assignment = initial_assignment(job.arch.balance, job.arch.locality, scene, spheres, units, costs);
  // Every sphere's SA x N and sa_n cost estimate, whatever the policy: scripts/figures
  // compares both with the measured cycles.
  const std::vector<double> weights = sa_n_weights(scene, spheres, costs);
  nlohmann::json sphere_info = nlohmann::json::array();
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const SphereDef& d = spheres[s];
    sphere_info.push_back({{"object", d.object}, {"primitives", d.prims.size()}, {"radius", d.local.r},
                           {"world_radius", d.world_radius()},
                           {"center", {d.local.c.x, d.local.c.y, d.local.c.z}}, {"sa_n", d.sa_n()},
                           {"sa_n_weight", weights[s]}, {"bvh_nodes", geometry.nodes_in(static_cast<std::uint32_t>(s))}});
  }
  if (o.trace_units) check_trace_units(*o.trace_units, job.trace.units, units);
  job.header = {{"scene", o.scene},
                {"sphere_list", sphere_info},
                {"triangles", scene.triangle_count()},
                {"objects", scene.objects.size()},
                {"spheres", spheres.size()},
                {"units", units},
                {"resolution", {job.width, job.height}},
                {"depth", job.arch.gpp.depth >= 0 ? job.arch.gpp.depth : scene.depth},
                {"arch", to_json(job.arch)},
                {"threads", thread_count()}};
  // The depth bound the frames are traced to, resolved: --depth, else gpp.depth, else the scene's.
  job.header["arch"]["gpp"]["depth"] = job.arch.gpp.depth >= 0 ? job.arch.gpp.depth : scene.depth;
  job.cost = std::make_shared<RunCost>(o.tech, job.arch, units, spheres.size());
  job.header.update(job.cost->header());
  if (job.arch.iu.model == IuModel::pipelined) {  // each unit's schedule: its II and latency
    const timing::PipelineSchedules p = timing::pipeline_schedules(job.arch);
    nlohmann::json stages = nlohmann::json::object();
    for (int s = 0; s < timing::kPipeStages; ++s) {
      if (!p.used[s]) continue;
      const FpUnits u = timing::stage_units(job.arch, static_cast<timing::PipeStage>(s), *p.stage[s].graph);
      stages[timing::to_string(static_cast<timing::PipeStage>(s))] = {
          {"ii", p.stage[s].ii}, {"latency", p.stage[s].length()}, {"adders", u.adders}, {"multipliers", u.multipliers}};
    }
    job.header["iu_stages"] = stages;
  }
  const LoadOptions load = load_options_for(o.load, o.max_object_triangles, object_split_named(job.arch.split, o.scene));
  job.header["load_options"] = {{"aff_max_object_triangles", load.aff.max_object_triangles},
                                {"aff_sphere_segments", load.aff.sphere_segments},
                                {"aff_sphere_rings", load.aff.sphere_rings},
                                {"aff_cone_segments", load.aff.cone_segments}};
  // --sample: the engine times the sample with its FIFOs scaled (or kept); the estimator reads it.
  job.engine_arch = job.arch;
  if (job.sample) {
    if (o.sample_fifos.value_or("scaled") == "scaled")
      job.engine_arch.fifo_depth = sampled_fifo_depth(job.arch.fifo_depth, *job.sample);
    job.estimator = std::make_shared<SampleEstimator>(job.arch, job.sample, job.engine_arch.fifo_depth, *job.cost);
  }
  if (job.arch.level == Level::analytic) {  // no SystemC at all
    simulate<T>(job, geometry);
    return 0;
  }
  // An exception out of sc_main would be reported by SystemC as "uncaught exception" (E549):
  // carry it out of the kernel and rethrow it here, for main to report.
  std::exception_ptr failure;
  g_simulation = [&] {
    try {
      simulate<T>(job, geometry);
    } catch (...) {
      failure = std::current_exception();
    }
    return 0;
  };
  // SystemC reports become exceptions (caught in main), never an abort.
  sc_core::sc_report_handler::set_actions(sc_core::SC_ERROR, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions(sc_core::SC_FATAL, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions("/OSCI/SystemC", sc_core::SC_INFO, sc_core::SC_DO_NOTHING);
  // An exception out of a process: reported once, by main, as itself (from_process).
  sc_core::sc_report_handler::set_actions(sc_core::SC_ID_SIMULATION_UNCAUGHT_EXCEPTION_, sc_core::SC_THROW);
  char arg0[] = "oprt";
  char* argv[] = {arg0, nullptr};
  const int rc = sc_core::sc_elab_and_sim(1, argv);
  g_simulation = nullptr;
  if (failure) std::rethrow_exception(from_process(failure, job));
  return rc;
}

// --sample's N (1: every pixel), and the options that only make sense with it.
std::uint32_t sample_fraction(const RenderOptions& o) {
  if (!o.sample) {
    if (o.seed) throw InputError("--seed", std::to_string(*o.seed), "chooses the pixels of --sample, which is not given");
    if (o.sample_fifos) throw InputError("--sample-fifos", *o.sample_fifos, "applies to --sample, which is not given");
    return 1;
  }
  return parse_sample_fraction(*o.sample, "--sample");
}

}  // namespace

int run_render(const RenderOptions& o) { return run_render(o, nullptr); }

int run_render(const RenderOptions& o, RenderCache* cache) {
  ::setenv("SYSTEMC_DISABLE_COPYRIGHT_MESSAGE", "1", 0);
  RenderJob job;
  job.arch = resolve_arch(o);
  const ObjectSplit split = object_split_named(job.arch.split, o.scene);
  job.arch.split = to_string(split);  // recorded in stats.json as resolved
  if (job.arch.level == Level::analytic && !o.vcd.empty())
    throw InputError("--vcd", o.vcd, "the analytic level has no simulated signals to trace (use --level at or lt)");
  if (job.arch.level == Level::analytic && !o.timeline.empty())
    throw InputError("--timeline", o.timeline,
                     "the analytic level has no simulated transactions to trace (use --level at or lt)");
  if (o.trace_buffer && o.vcd.empty())
    throw InputError("--trace-buffer", std::to_string(*o.trace_buffer),
                     "sizes the --vcd writer's buffer, and --vcd is not given");
  const std::uint32_t sample_n = sample_fraction(o);

  if (!o.tech.empty()) (void)load_tech(o.tech);  // its errors before anything else is read

  // Every output, before anything is loaded or written.
  Prepared p;
  OutputPlan& outputs = p.outputs;
  outputs.folder("--out", o.out, {"stats.json", "stats.csv"});
  outputs.file("--vcd", o.vcd, trace_companions(o.vcd));
  outputs.file("--timeline", o.timeline);
  outputs.input("scene file", o.scene);
  outputs.input("architecture file", o.arch_file);
  outputs.input("technology table", o.tech);
  if (!o.frames.empty()) {
    const FrameRange r = parse_frame_range(o.frames, "--frames");
    outputs.frames(r.first, r.last);
  }
  outputs.check();

  // Memory: what the run may use, and what it needs besides the scene's geometry, which the
  // loaders charge as they make it.
  p.limit = memory_limit(o.max_memory);
  p.shape.timed = true;
  p.shape.level = job.arch.level;
  p.shape.units = static_cast<std::uint64_t>(job.arch.ius);
  p.shape.bvh = job.arch.accel == "bvh";
  p.shape.double_precision = job.arch.precision == "double";
  p.shape.sram_bytes = job.arch.memory.sram_bytes;
  p.shape.line_bytes = static_cast<std::uint64_t>(job.arch.memory.cache.line_bytes);
  p.shape.trace_changes = o.vcd.empty() ? 0 : o.trace_buffer.value_or(VcdWriter::kDefaultBudget);
  p.shape.timeline = !o.timeline.empty();
  {
    int w = 0, h = 0;
    parse_resolution(o.resolution, w, h);
    const MemoryEstimate before = memory_estimate(p.shape, std::uint64_t(w) * std::uint64_t(h), 1,
                                                  {"--resolution", o.resolution});
    refuse_if_over(before, p.limit);
    limit_scene_memory(p.limit, p.shape, before);
  }

  const std::shared_ptr<const Scene> loaded = shared_scene(o.scene, load_options_for(o.load, o.max_object_triangles, split), cache);
  const Scene& scene = *loaded;
  job.scene = &scene;
  job.width = scene.width;
  job.height = scene.height;
  parse_resolution(o.resolution, job.width, job.height);
  if (sample_n > 1) job.sample = std::make_shared<const PixelSample>(job.width, job.height, sample_n, o.seed.value_or(0));
  job.frames = parse_frames(o.frames, scene);
  check_motions(scene, job.frames.first, job.frames.last);
  job.out_dir = o.out;
  job.vcd_path = o.vcd;
  job.timeline_path = o.timeline;
  job.trace = trace_selection(o, job.frames);
  if (o.trace_buffer) job.trace_budget = *o.trace_buffer;
  job.progress = o.progress && ::isatty(2);
  return job.arch.precision == "double" ? render<double>(o, scene, job, p, cache) : render<float>(o, scene, job, p, cache);
}

}  // namespace oprt
