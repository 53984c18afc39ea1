#include "testbench.h"

#include "frame_output.h"
#include "gtkwave.h"
#include "policy_driver.h"
#include "hw/watchdog.h"
#include "ref/frame_setup.h"
#include "ref/stop.h"

#include <cstdio>
#include <filesystem>
#include <optional>

namespace oprt {

using namespace sc_core;

namespace {

hw::FrameCommand frame_command(const RenderJob& job, int f, FrameImage& image) {
  hw::FrameCommand cmd;
  cmd.frame = f;
  cmd.to_world = object_matrices(*job.scene, f);
  cmd.camera = job.scene->camera->at(f);
  cmd.width = job.width;
  cmd.height = job.height;
  cmd.image = &image;
  return cmd;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <typename T>
class Testbench : public sc_module {
 public:
  SC_HAS_PROCESS(Testbench);
  Testbench(const sc_module_name& name, RenderJob& job, SceneGeometry<T>& geometry)
      : sc_module(name), job_(job), geometry_(geometry) {
    if (!job.vcd_path.empty()) vcd_ = std::make_unique<VcdWriter>(job.vcd_path);
    engine_ = std::make_unique<hw::Engine<T>>("engine", *job.scene, geometry, job.arch, job.assignment.units(),
                                              vcd_.get());
    engine_->assign(job.assignment);
    policy_ = std::make_unique<PolicyDriver<T>>(*job.scene, geometry, job.arch, job.assignment, job.width, job.height);
    if (job.progress)
      engine_->gpp().on_progress([this](std::uint64_t done, std::uint64_t total) { progress(done, total); });
    if (job.write_files) stats_ = std::make_unique<StatsWriter>(job.out_dir, job.header);
    SC_THREAD(run);
  }

 private:
  void run() {
    try {
      frames();
    } catch (...) {
      job_.error = std::current_exception();
    }
    sc_stop();
  }

  void frames() {
    bool set_up = false;
    for (int f = job_.frames.first; f <= job_.frames.last; ++f) {
      frame_ = f;
      const auto t0 = std::chrono::steady_clock::now();
      reset_stats();
      if (deforming_) update_deforming(geometry_, *job_.scene, f);
      job_.assignment = policy_->for_frame(f, previous_ ? &*previous_ : nullptr);
      engine_->assign(job_.assignment);
      if (!set_up) {  // load the object memories before the animation, outside every frame
        engine_->setup();
        reset_stats();
        set_up = true;
      }
      FrameImage image(job_.width, job_.height);
      hw::FrameCommand cmd = frame_command(job_, f, image);
      engine_->run_frame(cmd);
      previous_ = collect();
      const FrameStats fs = frame_stats(*previous_, job_, geometry_, f, seconds_since(t0), image);
      finish_frame(job_, stats_.get(), fs, std::move(image));
      last_frame_end_ = sc_time_stamp().value();
      if (vcd_) vcd_->flush_before(last_frame_end_);
    }
    close_trace(sc_time_stamp().value());
  }

 public:
  // After a stop request ended the simulation mid-frame: the trace ends with the last
  // completed frame (without one, the destructor removes the partial trace).
  void stopped() {
    if (job_.completed == 0 || !vcd_) return;
    vcd_->discard_from(last_frame_end_);
    close_trace(last_frame_end_);
  }

 private:
  void close_trace(std::uint64_t end_ps) {
    if (!vcd_) return;
    vcd_->close(end_ps);
    const auto vcd = std::filesystem::path(job_.vcd_path);
    std::vector<TraceSignal> signals;
    for (const auto& [name, width] : vcd_->variables()) signals.push_back({name, width});
    write_gtkwave_save(job_.vcd_path, (vcd.parent_path() / (vcd.stem().string() + ".gtkw")).string(), signals,
                       end_ps);
  }

  void reset_stats() {
    for (std::size_t u = 0; u < engine_->units(); ++u) {
      engine_->unit(u).reset_stats();
      engine_->memory(u).reset_stats();
      engine_->fifo(u).reset_counts();
    }
    engine_->bus().reset_stats();
  }

  // The frame as the modules counted it.
  hw::FrameRun collect() {
    const sc_time cycle(job_.arch.cycle_ns(), SC_NS);
    const hw::GppStats& g = engine_->gpp().stats();
    hw::FrameRun run;
    run.makespan = static_cast<std::uint64_t>((g.end - g.start) / cycle + 0.5);
    run.rays[0] = g.rays[0];
    run.rays[1] = g.rays[1];
    run.bus_busy = engine_->bus().busy_cycles();
    run.bus_bytes = engine_->bus().bytes();
    run.bus_transfers = engine_->bus().transfers();
    run.memory_load_bytes = g.memory_load_bytes;
    run.memory_load_cycles = g.memory_load_cycles;
    for (std::size_t u = 0; u < engine_->units(); ++u) {
      hw::UnitStats& s = engine_->unit(u).stats();
      hw::UnitRun r;
      r.cycles = s.cycles;
      r.rays = s.rays[0] + s.rays[1];
      r.memory_bytes = engine_->memory(u).bytes_read();
      r.pipeline = s.pipeline;
      hw::RayFifo& fifo = engine_->fifo(u);
      r.fifo_pushes = fifo.pushes();
      r.fifo_pops = fifo.pops();
      r.fifo_peak = fifo.peak_occupancy();
      if (u < g.unit_memory_load_bytes.size()) r.memory_load_bytes = g.unit_memory_load_bytes[u];
      run.units.push_back(r);
    }
    run.per_sphere = engine_->functional().per_sphere;
    return run;
  }

  void progress(std::uint64_t done, std::uint64_t total) {
    const int width = 30;
    const double f = total ? static_cast<double>(done) / total : 0;
    const int filled = static_cast<int>(f * width);
    std::fprintf(stderr, "\r\033[Kframe %d of %d:%d  [%s%s] %3.0f%% of primary rays", frame_, job_.frames.first,
                 job_.frames.last, std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(), 100 * f);
    std::fflush(stderr);
  }

  RenderJob& job_;
  SceneGeometry<T>& geometry_;
  const bool deforming_ = has_deforming(*job_.scene);
  int frame_ = 0;
  std::uint64_t last_frame_end_ = 0;  // ps
  std::unique_ptr<VcdWriter> vcd_;
  std::unique_ptr<hw::Engine<T>> engine_;
  std::unique_ptr<StatsWriter> stats_;
  std::unique_ptr<PolicyDriver<T>> policy_;
  std::optional<hw::FrameRun> previous_;
};

// The analytic level: the same frames, no SystemC.
template <typename T>
void run_analytic(RenderJob& job, SceneGeometry<T>& geometry) {
  const bool deforming = has_deforming(*job.scene);
  hw::AnalyticEngine<T> engine(*job.scene, geometry, job.arch);
  PolicyDriver<T> policy(*job.scene, geometry, job.arch, job.assignment, job.width, job.height);
  std::unique_ptr<StatsWriter> stats;
  if (job.write_files) stats = std::make_unique<StatsWriter>(job.out_dir, job.header);
  std::optional<hw::FrameRun> previous;
  for (int f = job.frames.first; f <= job.frames.last; ++f) {
    if (const int s = stop_signal())
      throw Interrupted(s, frames_completed(job.frames.first, job.frames.last, job.completed));
    const auto t0 = std::chrono::steady_clock::now();
    if (deforming) update_deforming(geometry, *job.scene, f);
    job.assignment = policy.for_frame(f, previous ? &*previous : nullptr);
    engine.assign(job.assignment);
    if (f == job.frames.first) engine.setup();
    FrameImage image(job.width, job.height);
    previous = engine.run_frame(frame_command(job, f, image));
    const hw::FrameRun& run = *previous;
    const FrameStats fs = frame_stats(run, job, geometry, f, seconds_since(t0), image);
    finish_frame(job, stats.get(), fs, std::move(image));
  }
}

}  // namespace

template <typename T>
void simulate(RenderJob& job, SceneGeometry<T>& geometry) {
  if (job.arch.level == Level::analytic) {
    run_analytic(job, geometry);
    return;
  }
  if (job.arch.level == Level::lt) tlm_utils::tlm_quantumkeeper::set_global_quantum(sc_time(job.arch.quantum_ns, SC_NS));
  Testbench<T> tb("testbench", job, geometry);
  sc_start();
  if (job.error) std::rethrow_exception(job.error);
  if (const int s = stop_signal()) {
    tb.stopped();
    throw Interrupted(s, frames_completed(job.frames.first, job.frames.last, job.completed));
  }
  if (job.completed != job.frames.count())
    hw::check_deadlock("frame " + std::to_string(job.frames.first + job.completed) + " is unfinished (" +
                       std::to_string(job.completed) + " of " + std::to_string(job.frames.count()) +
                       " frames completed)");
  if (job.completed != job.frames.count())
    throw std::runtime_error("simulation ended after " + std::to_string(job.completed) + " of " +
                             std::to_string(job.frames.count()) + " frames");
}

template void simulate<float>(RenderJob&, SceneGeometry<float>&);
template void simulate<double>(RenderJob&, SceneGeometry<double>&);

}  // namespace oprt
