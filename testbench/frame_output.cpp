#include "frame_output.h"

#include <cstdio>
#include <filesystem>

namespace oprt {

template <typename T>
FrameStats frame_stats(const timing::FrameRun& run, const RenderJob& job, const SceneGeometry<T>& geometry, int frame,
                       double wall_s, const FrameImage& image) {
  FrameStats fs;
  fs.frame = frame;
  fs.wall_s = wall_s;
  static_cast<timing::FrameFigures&>(fs) = run;
  fs.image_hash = image.hash();
  fs.frame_time_s = static_cast<double>(run.makespan) * job.arch.cycle_ns() * 1e-9;
  if (job.arch.iu.model == IuModel::pipelined) fs.pipeline = timing::pipeline_config(job.arch);
  if (job.arch.replicate) {
    std::vector<std::uint64_t> bytes;
    for (std::uint32_t s = 0; s < geometry.sphere_count(); ++s) bytes.push_back(geometry.memory_bytes(s));
    fs.replicating = true;
    fs.replicas = replicas(job.assignment, geometry.sphere_count());
    fs.replica_bytes = replica_bytes(job.assignment, bytes);
    for (std::uint64_t b : bytes) fs.geometry_bytes += b;
  }
  fs.sphere_cycles.assign(geometry.sphere_count(), 0);
  fs.sphere_entries.assign(geometry.sphere_count(), {});
  for (int k = 0; k < kRayKinds; ++k)
    for (std::uint32_t s = 0; s < geometry.sphere_count(); ++s) {
      fs.sphere_cycles[s] += work_cycles(run.per_sphere[k][s], job.arch.costs, job.arch.kernel).busy();
      fs.sphere_entries[s][k] += run.per_sphere[k][s].transforms;
    }
  for (std::size_t u = 0; u < run.units.size(); ++u) {
    const timing::UnitRun& r = run.units[u];
    UnitFrameStats us;
    static_cast<timing::UnitRun&>(us) = r;
    us.id = static_cast<int>(u);
    us.spheres = job.assignment.unit[u];
    for (std::uint32_t s : us.spheres) us.primitives += geometry.triangles_in(s);
    // Pipelined: idle while it holds no ray (its stall overlaps the stages' work).
    const std::uint64_t used = r.pipeline ? r.pipeline->occupied : r.cycles.busy() + r.cycles.stall;
    us.idle = fs.makespan > used ? fs.makespan - used : 0;
    us.config_bytes = us.spheres.size() * Bytes<T>::sphere_config;
    for (std::uint32_t s : us.spheres) us.memory_capacity_bytes += geometry.memory_bytes(s);
    fs.units.push_back(std::move(us));
  }
  if (job.cost) fs.energy = job.cost->frame(fs);
  if (job.estimator && run.sample) fs.sample = job.estimator->estimate(run, fs);
  return fs;
}

namespace {
// --sample: the sample and the full frame's estimates with their 95 % intervals.
void print_sample_line(const FrameStats& fs) {
  const SampleEstimate& e = *fs.sample;
  std::printf("           sample %s (%llu of %llu pixels): estimate makespan %.4g cycles [%.4g, %.4g]  frame time %.4g s",
              e.json["fraction_text"].get<std::string>().c_str(), e.json["pixels"].get<unsigned long long>(),
              e.json["frame_pixels"].get<unsigned long long>(), e.makespan, e.makespan_interval[0],
              e.makespan_interval[1], e.frame_time_s);
  if (e.energy) std::printf("  energy %.4g J [%.4g, %.4g]", *e.energy, e.energy_interval[0], e.energy_interval[1]);
  std::printf("%s\n", e.trusted ? "" : "  (not trusted: see the warning)");
}
}  // namespace

void finish_frame(RenderJob& job, StatsWriter* stats, const FrameStats& fs, FrameImage&& image) {
  if (job.write_files) {
    const auto dir = std::filesystem::path(job.out_dir);
    write_frame_files((dir / frame_name(fs.frame, "exr")).string(), (dir / frame_name(fs.frame, "png")).string(), image,
                      job.sample != nullptr);
    if (job.cost) stats->set_area(job.cost->area());
    stats->add(fs);
    if (job.progress) std::fprintf(stderr, "\r\033[K");
    std::printf("frame %4d  makespan %llu cycles  efficiency %.3f  %llu rays  %.2f s  (%.3g rays/s)\n", fs.frame,
                static_cast<unsigned long long>(fs.makespan), fs.efficiency(),
                static_cast<unsigned long long>(fs.total_rays()), fs.wall_s,
                static_cast<double>(fs.total_rays()) / std::max(fs.wall_s, 1e-9));
    if (fs.sample) print_sample_line(fs);
    std::fflush(stdout);
  }
  if (job.keep_results) {
    job.results.push_back(fs);
    job.images.push_back(std::move(image));
  }
  ++job.completed;
}

template FrameStats frame_stats(const timing::FrameRun&, const RenderJob&, const SceneGeometry<float>&, int, double,
                                const FrameImage&);
template FrameStats frame_stats(const timing::FrameRun&, const RenderJob&, const SceneGeometry<double>&, int, double,
                                const FrameImage&);

}  // namespace oprt
