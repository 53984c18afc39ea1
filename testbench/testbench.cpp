#include "testbench.h"

#include "gtkwave.h"

#include "ref/frame_setup.h"

#include <cstdio>
#include <filesystem>
#include <unistd.h>

namespace oprt {

using namespace sc_core;

namespace {

template <typename T>
class Testbench : public sc_module {
 public:
  SC_HAS_PROCESS(Testbench);
  Testbench(const sc_module_name& name, RenderJob& job, const SceneGeometry<T>& geometry)
      : sc_module(name), job_(job), geometry_(geometry) {
    if (!job.vcd_path.empty()) vcd_ = std::make_unique<VcdWriter>(job.vcd_path);
    engine_ = std::make_unique<hw::Engine<T>>("engine", *job.scene, geometry, job.arch, job.assignment.units(),
                                              vcd_.get());
    engine_->assign(job.assignment);
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
    const sc_time cycle(job_.arch.cycle_ns(), SC_NS);
    for (int f = job_.frames.first; f <= job_.frames.last; ++f) {
      frame_ = f;
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t u = 0; u < engine_->units(); ++u) engine_->unit(u).reset_stats();
      engine_->bus().reset_stats();
      for (std::size_t u = 0; u < engine_->units(); ++u) engine_->memory(u).reset_stats();
      FrameImage image(job_.width, job_.height);
      hw::FrameCommand cmd;
      cmd.frame = f;
      cmd.to_world = object_matrices(*job_.scene, f);
      cmd.camera = job_.scene->camera->at(f);
      cmd.width = job_.width;
      cmd.height = job_.height;
      cmd.image = &image;
      engine_->run_frame(cmd);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

      FrameStats fs;
      fs.frame = f;
      fs.wall_s = wall;
      const hw::GppStats& g = engine_->gpp().stats();
      fs.makespan = static_cast<std::uint64_t>((g.end - g.start) / cycle + 0.5);
      fs.rays[0] = g.rays[0];
      fs.rays[1] = g.rays[1];
      fs.bus_busy = engine_->bus().busy_cycles();
      fs.bus_bytes = engine_->bus().bytes();
      fs.bus_transfers = engine_->bus().transfers();
      fs.image_hash = image.hash();
      for (std::size_t u = 0; u < engine_->units(); ++u) {
        hw::UnitStats& s = engine_->unit(u).stats();
        UnitFrameStats us;
        us.id = static_cast<int>(u);
        us.spheres = job_.assignment.unit[u];
        for (std::uint32_t sp : us.spheres) us.primitives += geometry_.triangles_in(sp);
        us.rays = s.rays[0] + s.rays[1];
        us.cycles = s.cycles;
        const std::uint64_t used = s.cycles.busy() + s.cycles.stall;
        us.idle = fs.makespan > used ? fs.makespan - used : 0;
        for (int k = 0; k < kRayKinds; ++k)
          for (std::uint32_t sp : us.spheres) us.work[k] += s.per_sphere[k][sp];
        us.memory_bytes = engine_->memory(u).bytes_read();
        fs.units.push_back(std::move(us));
      }
      if (job_.write_files) {
        const auto dir = std::filesystem::path(job_.out_dir);
        write_exr((dir / frame_name(f, "exr")).string(), image);
        write_png((dir / frame_name(f, "png")).string(), image);
        stats_->add(fs);
      }
      if (job_.keep_results) {
        job_.results.push_back(fs);
        job_.images.push_back(std::move(image));
      }
      if (vcd_) vcd_->flush_before(sc_time_stamp().value());
      ++job_.completed;
      if (job_.write_files) report(fs);
    }
    if (vcd_) {
      vcd_->close(sc_time_stamp().value());
      const auto vcd = std::filesystem::path(job_.vcd_path);
      std::vector<TraceSignal> signals;
      for (const auto& [name, width] : vcd_->variables()) signals.push_back({name, width});
      write_gtkwave_save(job_.vcd_path, (vcd.parent_path() / (vcd.stem().string() + ".gtkw")).string(), signals,
                         sc_time_stamp().value());
    }
  }

  void progress(std::uint64_t done, std::uint64_t total) {
    const int width = 30;
    const double f = total ? static_cast<double>(done) / total : 0;
    const int filled = static_cast<int>(f * width);
    std::fprintf(stderr, "\r\033[Kframe %d of %d:%d  [%s%s] %3.0f%% of primary rays", frame_, job_.frames.first,
                 job_.frames.last, std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(), 100 * f);
    std::fflush(stderr);
  }

  void report(const FrameStats& fs) {
    if (job_.progress) std::fprintf(stderr, "\r\033[K");
    std::printf("frame %4d  makespan %llu cycles  efficiency %.3f  %llu rays  %.2f s  (%.3g rays/s)\n", fs.frame,
                static_cast<unsigned long long>(fs.makespan), fs.efficiency(),
                static_cast<unsigned long long>(fs.rays[0] + fs.rays[1]), fs.wall_s,
                (fs.rays[0] + fs.rays[1]) / std::max(fs.wall_s, 1e-9));
    std::fflush(stdout);
  }

  RenderJob& job_;
  const SceneGeometry<T>& geometry_;
  int frame_ = 0;
  std::unique_ptr<VcdWriter> vcd_;
  std::unique_ptr<hw::Engine<T>> engine_;
  std::unique_ptr<StatsWriter> stats_;
};

}  // namespace

template <typename T>
void simulate(RenderJob& job, const SceneGeometry<T>& geometry) {
  if (job.arch.level == Level::lt) tlm_utils::tlm_quantumkeeper::set_global_quantum(sc_time(job.arch.quantum_ns, SC_NS));
  Testbench<T> tb("testbench", job, geometry);
  sc_start();
  if (job.error) std::rethrow_exception(job.error);
  if (job.completed != job.frames.count())
    throw std::runtime_error("simulation ended after " + std::to_string(job.completed) + " of " +
                             std::to_string(job.frames.count()) + " frames");
}

template void simulate<float>(RenderJob&, const SceneGeometry<float>&);
template void simulate<double>(RenderJob&, const SceneGeometry<double>&);

}  // namespace oprt
