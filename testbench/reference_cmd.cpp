// oprt reference: the untimed functional renderer; frames, previews and work counts.
#include "balance/spheres.h"
#include "commands.h"
#include "frame_log.h"
#include "memory_estimate.h"
#include "options.h"
#include "outputs.h"
#include "ref/parallel.h"
#include "ref/reference.h"
#include "ref/stop.h"
#include "scene/load.h"
#include "stats.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace oprt {

namespace {

template <typename T>
int reference(const CommonOptions& o, const Scene& scene, const OutputPlan& outputs, const MemoryLimit& limit,
              const RunShape& shape) {
  int width = scene.width, height = scene.height;
  parse_resolution(o.resolution, width, height);
  const FrameRange frames = parse_frames(o.frames, scene);
  check_motions(scene, frames.first, frames.last);
  std::uint64_t vertices = 0;
  for (const Object& obj : scene.objects) vertices += obj.mesh.vertices.size();
  MemoryEstimate need = memory_estimate(
      shape, std::uint64_t(width) * std::uint64_t(height), 1,
      o.resolution.empty() ? NumberSource{o.scene, "its image, " + std::to_string(width) + "x" + std::to_string(height)}
                           : NumberSource{"--resolution", o.resolution});
  add_geometry(need, shape, vertices, scene.triangle_count(), o.scene);
  refuse_if_over(need, limit);
  const auto t_build = std::chrono::steady_clock::now();
  const Kernel kernel = kernel_named(o.kernel).value_or(Kernel::moller);
  const ObjectSplit split = object_split_named(o.split, o.scene);
  SceneGeometry<T> g = build_geometry<T>(scene, make_spheres(scene, o.subdivide, SplitRule::balanced_san, split), kernel,
                                         accel_named(o.accel));
  const bool deforming = has_deforming(scene);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_build).count();
  outputs.create_folders();

  nlohmann::json stats = {{"scene", o.scene},
                          {"precision", o.precision},
                          {"accel", o.accel},
                          {"kernel", to_string(kernel)},
                          {"triangle_exit_stages", {stage_names(kernel)[0], stage_names(kernel)[1],
                                                    stage_names(kernel)[2], stage_names(kernel)[3]}},
                          {"resolution", {width, height}},
                          {"split", to_string(split)},
                          {"spheres", g.sphere_count()},
                          {"triangles", scene.triangle_count()},
                          {"build_s", build_s},
                          {"threads", thread_count()}};
  // reference.json: written when the run ends or is stopped, listing the frames completed.
  FrameLog log((std::filesystem::path(o.out) / "reference.json").string());
  int completed = 0;
  for (int f = frames.first; f <= frames.last; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    if (deforming) update_deforming(g, scene, f);
    FrameResult r;
    try {
      r = render_reference(scene, g, f, width, height, o.depth.value_or(-1));
    } catch (const Interrupted& e) {
      log.write(stats);
      throw Interrupted(e.signal(), frames_completed(frames.first, frames.last, completed));
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string exr = (std::filesystem::path(o.out) / frame_name(f, "exr")).string();
    write_frame_files(exr, (std::filesystem::path(o.out) / frame_name(f, "png")).string(), r.image);
    std::uint64_t rays = 0;
    nlohmann::json rays_json, work, per_object = nlohmann::json::array();
    std::string kinds_text;
    for (int k = 0; k < kRayKinds; ++k) {
      rays += r.work.rays[k];
      rays_json[kRayKindNames[k]] = r.work.rays[k];
      work[kRayKindNames[k]] = work_json(r.work.total(static_cast<RayKind>(k)));
      if (r.work.rays[k] || k < 2)
        kinds_text += (k ? ", " : "") + std::to_string(r.work.rays[k]) + " " + kRayKindNames[k];
    }
    for (std::size_t obj = 0; obj < scene.objects.size(); ++obj) {
      nlohmann::json o = {{"object", obj}, {"name", scene.objects[obj].name}};
      for (int k = 0; k < kRayKinds; ++k) {
        WorkCounts w;
        for (std::uint32_t s = 0; s < g.sphere_count(); ++s)
          if (g.object[s] == obj) w += r.work.per_sphere[k][s];
        o[kRayKindNames[k]] = work_json(w);
      }
      per_object.push_back(std::move(o));
    }
    nlohmann::json by_depth = nlohmann::json::array();  // as render's ray_kinds.by_depth
    for (std::size_t d = 0; d < r.work.by_depth.size(); ++d) {
      nlohmann::json row = {{"depth", d}};
      for (int k = 0; k < kRayKinds; ++k)
        if (k < 2 || r.work.rays[k]) row[kRayKindNames[k]] = r.work.by_depth[d][k];
      by_depth.push_back(std::move(row));
    }
    log.add({{"frame", f},
             {"wall_s", wall},
             {"depth", o.depth.value_or(scene.depth)},
             {"rays", rays_json},
             {"by_depth", by_depth},
             {"rays_per_s", rays / wall},
             {"work", work},
             {"objects", per_object}});
    std::printf("frame %4d  %.3f s  %llu rays (%s)  %.3g M triangle tests%s  -> %s\n", f, wall,
                (unsigned long long)rays, kinds_text.c_str(), r.work.total().tri_tests() / 1e6,
                g.has_bvh() ? ("  " + std::to_string(r.work.total().box_tests) + " box tests").c_str() : "",
                exr.c_str());
    std::fflush(stdout);
    ++completed;
  }
  log.write(stats);
  return 0;
}

}  // namespace

int run_reference(const CommonOptions& o) {
  OutputPlan outputs;
  outputs.folder("--out", o.out, {"reference.json"});
  outputs.input("scene file", o.scene);
  if (!o.frames.empty()) {
    const FrameRange r = parse_frame_range(o.frames, "--frames");
    outputs.frames(r.first, r.last);
  }
  outputs.check();
  const MemoryLimit limit = memory_limit(o.max_memory);
  RunShape shape;
  shape.timed = false;
  shape.bvh = o.accel == "bvh";
  shape.double_precision = o.precision == "double";
  {
    int w = 0, h = 0;
    parse_resolution(o.resolution, w, h);
    const MemoryEstimate before =
        memory_estimate(shape, std::uint64_t(w) * std::uint64_t(h), 1, {"--resolution", o.resolution});
    refuse_if_over(before, limit);
    limit_scene_memory(limit, shape, before);
  }
  const Scene scene =
      load_scene(o.scene, load_options_for(o.load, o.max_object_triangles, object_split_named(o.split, o.scene)));
  return o.precision == "double" ? reference<double>(o, scene, outputs, limit, shape)
                                 : reference<float>(o, scene, outputs, limit, shape);
}

}  // namespace oprt
