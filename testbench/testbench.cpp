#include "testbench.h"

#include "frame_output.h"
#include "gtkwave.h"
#include "balance/policy_driver.h"
#include "hw/watchdog.h"
#include "ref/balance_inputs.h"
#include "ref/frame_setup.h"
#include "timing/measured_frame.h"
#include "ref/stop.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace oprt {

using namespace sc_core;

namespace {

timing::FrameCommand frame_command(const RenderJob& job, int f, FrameImage& image) {
  timing::FrameCommand cmd;
  cmd.frame = f;
  cmd.to_world = object_matrices(*job.scene, f);
  cmd.camera = job.scene->camera->at(f);
  cmd.width = job.width;
  cmd.height = job.height;
  cmd.image = &image;
  cmd.sample = job.sample.get();
  return cmd;
}

// What the balance policy reads of a frame: with --sample, expanded to the full frame.
MeasuredFrame measured(const timing::FrameRun& run, const RenderJob& job) {
  const MeasuredFrame m = timing::measured_frame(run, job.arch);
  return job.estimator ? job.estimator->expanded(m) : m;
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
    open_traces();
    engine_ = std::make_unique<hw::Engine<T>>("engine", *job.scene, geometry, job.engine_arch, job.assignment.units(),
                                              vcd_.get(), timeline_.get());
    engine_->assign(job.assignment);
    // memory.dram.path "external": the engine's memory port gets oprt's own DRAM model, with
    // the figures of "channel" (the same channels, latency and rate; tests/golden).
    if (engine_->memory_port_used()) {
      memory_ = std::make_unique<hw::Dram>("dram", job.engine_arch, job.assignment.units(), hw::addr::dram_base);
      engine_->mem.bind(memory_->in);
    }
    policy_ = std::make_unique<PolicyDriver>(*job.scene, policy_inputs(*job.scene, geometry, job.arch), job.arch,
                                             job.assignment, job.width, job.height);
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
      engine_->reset_stats();
      if (deforming_) update_deforming(geometry_, *job_.scene, f);
      job_.assignment = policy_->for_frame(f, previous_ ? &*previous_ : nullptr);
      engine_->assign(job_.assignment);
      if (!set_up) {  // load the object memories before the animation, outside every frame
        engine_->setup();
        engine_->reset_stats();
        set_up = true;
      }
      FrameImage image(job_.width, job_.height);
      if (job_.sample) mark_not_traced(image, job_.sample->pixels());  // the GPP writes the pixels it traces
      timing::FrameCommand cmd = frame_command(job_, f, image);
      const TraceSelection& sel = job_.trace;
      if (sel.frames && f == sel.frames->first)
        set_trace_window(std::max<std::uint64_t>(sel.from_ps, sc_time_stamp().value()), sel.to_ps);
      engine_->run_frame(cmd);
      const timing::FrameRun run = engine_->figures();
      const FrameStats fs = frame_stats(run, job_, geometry_, f, seconds_since(t0), image);
      previous_ = measured(run, job_);  // after the estimate: it knows the frame's expansion
      finish_frame(job_, stats_.get(), fs, std::move(image));
      last_frame_end_ = sc_time_stamp().value();
      if (vcd_) vcd_->flush_before(last_frame_end_);
      if (sel.frames && f == sel.frames->last)
        set_trace_window(trace_from_, std::min<std::uint64_t>(sel.to_ps, last_frame_end_));
    }
    if (stats_) stats_->finish();
    close_trace(sc_time_stamp().value());
  }

  // The waveform and the timeline, with what --trace-* selects. With --trace-frames the
  // window opens when the first traced frame starts (set_trace_window) and closes when the
  // last one ends; every signal is at its rest value between frames, so nothing before is lost.
  void open_traces() {
    const TraceSelection& sel = job_.trace;
    const std::uint64_t from = sel.frames ? VcdWriter::kNever : sel.from_ps;
    if (!job_.vcd_path.empty()) {
      vcd_ = std::make_unique<VcdWriter>(job_.vcd_path);
      vcd_->set_filter(
          [&sel](const std::string& scope, const std::string& name) { return sel.traces_signal(scope, name); });
      vcd_->set_horizon([this] {  // no process reports behind simulation time, nor a pipelined unit behind its floor
        sc_time::value_type h = sc_time_stamp().value();
        if (engine_ && job_.arch.iu.model == IuModel::pipelined)
          for (std::size_t u = 0; u < engine_->units(); ++u) h = std::min(h, engine_->unit(u).trace_floor().value());
        return h;
      });
      vcd_->set_budget(job_.trace_budget);
    }
    if (!job_.timeline_path.empty()) {
      timeline_ = std::make_unique<TimelineWriter>(job_.timeline_path);
      timeline_->set_filter(
          [&sel](const std::string& scope, const std::string& group) { return sel.traces(scope, group); });
    }
    set_trace_window(from, sel.to_ps);
  }

  void set_trace_window(std::uint64_t from, std::uint64_t to) {
    trace_from_ = from;
    if (vcd_) vcd_->set_window(from, to);
    if (timeline_) timeline_->set_window(from, to);
  }

 public:
  // After a stop request ended the simulation mid-frame: the trace ends with the last
  // completed frame (without one, the destructor removes the partial trace).
  // The waveform may have been written past that, up to the simulation time it reached
  // (it is flushed within frames): it ends there.
  void stopped() {
    if (job_.completed == 0) return;
    if (stats_) stats_->finish();
    std::uint64_t end = last_frame_end_;
    if (vcd_) {
      end = std::max(end, vcd_->flushed());
      vcd_->discard_from(end);
    }
    close_trace(end);
  }

 private:
  void close_trace(std::uint64_t end_ps) {
    if (timeline_) {
      timeline_->close();
      std::printf("timeline %s  %.1f MB  %llu slices\n", job_.timeline_path.c_str(),
                  static_cast<double>(std::filesystem::file_size(job_.timeline_path)) / 1e6,
                  static_cast<unsigned long long>(timeline_->slices()));
    }
    if (!vcd_) return;
    const std::uint64_t from = vcd_->window_from();
    vcd_->close(end_ps);
    std::printf("trace    %s  %.1f MB  %s to %s  (at most %zu changes held at once)\n", job_.vcd_path.c_str(),
                static_cast<double>(std::filesystem::file_size(job_.vcd_path)) / 1e6,
                format_time_ps(vcd_->dump_start()).c_str(), format_time_ps(vcd_->dump_end()).c_str(),
                vcd_->peak_buffered());
    if (from >= end_ps && from != VcdWriter::kNever && end_ps > 0)
      std::fprintf(stderr,
                   "oprt: warning: the trace window opens at %s, after the run ended (%s): %s holds no change\n",
                   format_time_ps(from).c_str(), format_time_ps(end_ps).c_str(), job_.vcd_path.c_str());
    const auto vcd = std::filesystem::path(job_.vcd_path);
    std::vector<TraceSignal> signals;
    for (const auto& [name, width] : vcd_->variables()) signals.push_back({name, width});
    write_gtkwave_save(job_.vcd_path, (vcd.parent_path() / (vcd.stem().string() + ".gtkw")).string(), signals,
                       vcd_->dump_start(), vcd_->dump_end());
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
  std::uint64_t trace_from_ = 0;      // ps: where the trace window opens
  std::unique_ptr<VcdWriter> vcd_;
  std::unique_ptr<TimelineWriter> timeline_;
  std::unique_ptr<hw::Engine<T>> engine_;
  std::unique_ptr<hw::Dram> memory_;  // behind the engine's memory port ("external")
  std::unique_ptr<StatsWriter> stats_;
  std::unique_ptr<PolicyDriver> policy_;
  std::optional<MeasuredFrame> previous_;  // what the frame before measured, for the balance policy
};

// The analytic level: the same frames, no SystemC.
template <typename T>
void run_analytic(RenderJob& job, SceneGeometry<T>& geometry) {
  const bool deforming = has_deforming(*job.scene);
  analytic::AnalyticEngine<T> engine(*job.scene, geometry, job.engine_arch);
  PolicyDriver policy(*job.scene, policy_inputs(*job.scene, geometry, job.arch), job.arch, job.assignment, job.width,
                      job.height);
  std::unique_ptr<StatsWriter> stats;
  if (job.write_files) stats = std::make_unique<StatsWriter>(job.out_dir, job.header);
  std::optional<MeasuredFrame> previous;
  for (int f = job.frames.first; f <= job.frames.last; ++f) {
    if (const int s = stop_signal())
      throw Interrupted(s, frames_completed(job.frames.first, job.frames.last, job.completed));
    const auto t0 = std::chrono::steady_clock::now();
    if (deforming) update_deforming(geometry, *job.scene, f);
    job.assignment = policy.for_frame(f, previous ? &*previous : nullptr);
    engine.assign(job.assignment);
    if (f == job.frames.first) engine.setup();
    FrameImage image(job.width, job.height);
    const timing::FrameRun run = engine.run_frame(frame_command(job, f, image));
    const FrameStats fs = frame_stats(run, job, geometry, f, seconds_since(t0), image);
    previous = measured(run, job);  // after the estimate: it knows the frame's expansion
    finish_frame(job, stats.get(), fs, std::move(image));
  }
  if (stats) stats->finish();
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
