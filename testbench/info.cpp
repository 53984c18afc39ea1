// oprt info: what the engine will hold for a scene.
#include "balance/partition_quality.h"
#include "balance/policy.h"
#include "balance/spheres.h"
#include "commands.h"
#include "memory_estimate.h"
#include "geom/bounding_sphere.h"
#include "arch/cycle_schedule.h"
#include "options.h"
#include "ref/balance_inputs.h"
#include "ref/frame_setup.h"
#include "render.h"
#include "base/error.h"
#include "scene/load.h"

#include <algorithm>
#include <cstdio>

namespace oprt {

namespace {

// The assignment a render with this architecture starts from, and what it buys when rays go
// only to the units whose bound they enter (balance/partition_quality.h).
void print_assignment(const Arch& arch, const Scene& scene, const std::vector<SphereDef>& spheres) {
  const SceneGeometry<float> g = build_geometry<float>(scene, spheres, arch.kernel, accel_named(arch.accel));
  const SaNCosts costs = sa_n_costs(arch, g);
  const std::size_t units = units_for(spheres.size(), static_cast<std::size_t>(arch.ius));
  const Assignment a = initial_assignment(arch.balance, arch.locality, scene, spheres, units, costs);
  const PartitionQuality q = partition_quality(a, sphere_world_boxes(scene, spheres, 0), sa_n_weights(scene, spheres, costs));
  std::string policy = arch.balance;
  const nlohmann::json resolved = to_json(arch);
  if (resolved.contains("locality")) {
    char f[32];
    std::snprintf(f, sizeof f, ", locality %g", resolved["locality"].get<double>());
    policy += f;
  }
  std::printf("\nassignment  %s: %zu spheres on %zu units, at frame 0%s\n", policy.c_str(), spheres.size(), units,
              arch.balance == "feedback" || arch.balance == "view" ? " (re-balanced every frame after it)" : "");
  std::printf("estimated   fan-out %.4f units per ray entering the scene's box (the units' box areas over its)\n",
              q.fanout);
  std::printf("estimated   imbalance %.4f (the largest unit's sa_n cost over the mean; accel %s)\n", q.imbalance,
              arch.accel.c_str());
  const double scene_area = q.scene_bound.surface_area();
  std::printf("\n%6s %8s %14s %12s\n", "unit", "spheres", "sa_n cost", "box / scene");
  for (std::size_t u = 0; u < units; ++u)
    std::printf("%6zu %8zu %14.2f %12.4f\n", u, a.unit[u].size(), q.unit_load[u],
                scene_area > 0 ? q.unit_bound[u].surface_area() / scene_area : 1.0);
}

// The vertex normals and the Whitted terms the file published (scene.h): the normals are
// interpolated for shading, the terms traced as reflection and refraction rays (ref/shading.h).
void print_normals_and_materials(const Scene& scene) {
  std::size_t with_normals = 0;
  for (const Object& o : scene.objects) with_normals += o.mesh.triangles_with_normals();
  std::printf("normals     %zu of %zu triangles carry vertex normals (interpolated for shading)\n",
              with_normals, scene.triangle_count());
  std::vector<bool> used(scene.materials.size(), false);
  for (const Object& o : scene.objects) used[o.material] = true;
  std::size_t reflective = 0, transmissive = 0, in_use = 0;
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    if (!used[m]) continue;
    ++in_use;
    reflective += scene.materials[m].reflects();
    transmissive += scene.materials[m].transmits();
  }
  std::printf("materials   %zu used, %zu reflective, %zu transmissive (reflection and refraction rays to depth %d, "
              "the scene's bound)\n",
              in_use, reflective, transmissive, scene.depth);
  if (reflective + transmissive == 0) return;
  std::printf("%10s  %-28s %26s %26s %8s\n", "material", "name", "reflect", "transmit", "ior");
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (!used[m] || !(mat.reflects() || mat.transmits())) continue;
    std::printf("%10zu  %-28.28s (%6.4g, %6.4g, %6.4g) (%6.4g, %6.4g, %6.4g) %8.4g\n", m, mat.name.c_str(),
                mat.reflect.x, mat.reflect.y, mat.reflect.z, mat.transmit.x, mat.transmit.y, mat.transmit.z, mat.ior);
  }
}

}  // namespace

int run_info(const CommonOptions& o, const RenderOptions& arch_options) {
  if (o.schedules) {
    for (const OpGraph* g : {&sphere_textbook_graph(), &sphere_stable_graph(), &transform_graph(), &moller_graph(),
                              &transform_watertight_graph(), &watertight_graph(), &box_setup_graph(),
                              &box_graph(), &top_node_graph()}) {
      const Schedule s = list_schedule(*g);
      std::printf("%s\n", s.table().c_str());
    }
    // The pipelined IU's units at their default (a unit per op: II 1, latency 1 per op).
    for (const OpGraph* g : {&top_node_graph(), &sphere_stable_graph(), &transform_graph(),
                              &transform_box_setup_graph(Kernel::moller), &box_graph(), &moller_graph(),
                              &transform_watertight_graph(), &transform_box_setup_graph(Kernel::watertight),
                              &watertight_graph()})
      std::printf("%s\n", modulo_schedule(*g, full_units(*g)).table().c_str());
    if (o.scene.empty()) return 0;
  }
  if (o.scene.empty()) throw InputError("oprt info", "SCENE", "a scene file is required (or --schedules)");
  RenderOptions ro = arch_options;
  ro.split = o.split;
  const Arch arch = resolve_arch(ro);
  const ObjectSplit split = object_split_named(arch.split, o.scene);
  RunShape shape;
  shape.timed = false;
  limit_scene_memory(memory_limit(std::nullopt), shape, memory_estimate(shape, 0, 1));
  const Scene scene = load_scene(o.scene, load_options_for(o.load, o.max_object_triangles, split));
  const auto spheres = make_spheres(scene, arch.subdivide, split_rule_named(arch.split_rule), split);
  std::printf("scene       %s\n", o.scene.c_str());
  std::printf("image       %dx%d, %d frame%s, %zu light%s\n", scene.width, scene.height, scene.frame_count,
              scene.frame_count == 1 ? "" : "s", scene.lights.size(), scene.lights.size() == 1 ? "" : "s");
  std::printf("triangles   %zu\n", scene.triangle_count());
  std::printf("objects     %zu\n", scene.objects.size());
  std::printf("spheres     %zu (split %s, subdivide %d)\n", spheres.size(), to_string(split), arch.subdivide);
  for (const auto& n : scene.notes) std::printf("note        %s\n", n.c_str());
  print_normals_and_materials(scene);
  // Radius in the object's units and in the world's (times the object's stretch at frame
  // 0); area and SA x N are the world's, as the balance estimates use them.
  std::printf("\n%6s %6s  %-20s %30s %10s %10s %12s %8s %14s\n", "sphere", "object", "name", "centre (local)",
              "r (local)", "r (world)", "area", "prims", "SA x N");
  double sum_san = 0, sum_r = 0, sum_ritter = 0;
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const SphereDef& d = spheres[s];
    const Object& obj = scene.objects[d.object];
    std::printf("%6zu %6u  %-20.20s (%8.3f, %8.3f, %8.3f) %10.4f %10.4f %12.4f %8zu %14.2f\n", s, d.object,
                obj.name.c_str(), d.local.c.x, d.local.c.y, d.local.c.z, d.local.r, d.world_radius(),
                d.surface_area(), d.prims.size(), d.sa_n());
    sum_san += d.sa_n();
    sum_r += d.local.r;
    std::vector<Vec3d> pts;
    for (auto p : d.prims)
      for (auto k : obj.mesh.triangles[p]) pts.push_back(obj.mesh.vertices[k]);
    sum_ritter += ritter_sphere(pts).r;
  }
  std::printf("\nsum of SA x N  %.6g\n", sum_san);
  std::printf("radii: minimal enclosing spheres (Welzl) sum %.6g; Ritter's approximation would be %.4fx\n",
              sum_r, sum_ritter / sum_r);
  // What the units hold: the radius enclosing the float-rounded triangles, rounded up, and
  // at frame 0 the world radius with its rounding margin (ref/frame_setup.cpp).
  const SceneGeometry<float> g = build_geometry<float>(scene, spheres);
  const FrameSetup<float> f = setup_frame(scene, g, 0);
  double worst_local = 1, worst_world = 1;
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    worst_local = std::max(worst_local, g.local_sphere[s].r / spheres[s].local.r);
    const double stretch = max_stretch(f.placement[g.object[s]].to_world);
    worst_world = std::max(worst_world, f.world_sphere[s].r / (spheres[s].local.r * stretch));
  }
  std::printf("radii held by the units / minimal: local (float) at most %.9f, world at frame 0 at most %.9f\n",
              worst_local, worst_world);
  if (!ro.arch_file.empty() || ro.ius || ro.balance || ro.locality) print_assignment(arch, scene, spheres);
  return 0;
}

}  // namespace oprt
