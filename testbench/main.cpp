// oprt: the command line of the object-parallel ray-tracing engine model.
//   oprt render SCENE ...     the timed SystemC model
//   oprt reference SCENE ...  the untimed functional reference
//   oprt info SCENE ...       scene, spheres and their assignment
//   oprt compare A.exr B.exr  how far frame A is from reference frame B (JSON)
// Any bad input ends with one message "oprt: FILE: PLACE: PROBLEM" and exit status 2.
#include "commands.h"
#include "render.h"
#include "ref/parallel.h"
#include "ref/stop.h"
#include "scene/error.h"

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv) {
  using namespace oprt;
  CLI::App app{"oprt: a SystemC/TLM-2.0 model of an object-parallel ray-tracing engine for animated scenes"};
  app.require_subcommand(1);
  CommonOptions opt;
  int threads = 0;  // 0: every core
  auto add_threads = [&threads](CLI::App* sub) {
    sub->add_option("--threads", threads, "threads for the functional work (default: every core)")
        ->check(CLI::Range(1, 4096));
  };

  auto add_scene = [&](CLI::App* sub) {
    sub->add_option("SCENE", opt.scene, "scene file (.json, .aff, .gltf, .glb)")->required();
  };
  // How a BART .aff scene becomes objects (docs/aff.md).
  auto add_load_options = [](CLI::App* sub, LoadOptions& load, std::string& split,
                             std::optional<std::size_t>& max_object_triangles) {
    sub->add_option("--split", split,
                    "count | extent: how objects become spheres (default: extent for .aff and glTF, count for .json)")
        ->check(CLI::IsMember({"count", "extent"}));
    sub->add_option("--max-object-triangles", max_object_triangles,
                    "AFF: split static and rigid groups into objects of at most N triangles (0: never; default "
                    "4096 under --split count, 0 under extent)")
        ->check(CLI::Range(0, 1 << 30));
    sub->add_option_function<unsigned>(
           "--tessellation",
           [&load](unsigned n) {
             load.aff.sphere_segments = load.aff.cone_segments = n;
             load.aff.sphere_rings = n / 2;
           },
           "AFF: spheres get N segments and N/2 rings, cones N segments (default 16)")
        ->check(CLI::Range(4, 4096));
  };
  auto* info = app.add_subcommand("info", "print the scene, its bounding spheres and their SA x N");
  info->add_option("SCENE", opt.scene, "scene file (.json, .aff, .gltf, .glb)");
  info->add_flag("--schedules", opt.schedules, "print the IU operations' cycle schedules");
  RenderOptions info_arch;  // with any of --arch, --ius, --balance, --locality: the assignment too
  info->add_option("--subdivide", info_arch.subdivide, "split each object's sphere into K")->check(CLI::Range(1, 4096));
  info->add_option("--arch", info_arch.arch_file, "architecture file (JSON, oprt-arch/1)");
  info->add_option("--ius", info_arch.ius, "number of intersection units");
  info->add_option("--balance", info_arch.balance, "paper | round_robin | sa_n | spatial | feedback | view (frame 0)")
      ->check(CLI::IsMember({"paper", "round_robin", "sa_n", "spatial", "feedback", "view"}));
  info->add_option("--locality", info_arch.locality, "spatial, feedback: tight unit bounds (1) against balance (0)");
  info->add_option("--accel", info_arch.accel, "brute | bvh: what the sa_n cost estimate assumes inside a sphere")
      ->check(CLI::IsMember({"brute", "bvh"}));
  add_load_options(info, opt.load, opt.split, opt.max_object_triangles);

  auto* ref = app.add_subcommand("reference", "render with the untimed functional reference");
  add_scene(ref);
  ref->add_option("--precision", opt.precision, "float | double")->check(CLI::IsMember({"float", "double"}));
  ref->add_option("--kernel", opt.kernel, "moller | watertight")->check(CLI::IsMember({"moller", "watertight"}));
  ref->add_option("--frames", opt.frames, "N or A:B (inclusive); default: every frame");
  ref->add_option("--resolution", opt.resolution, "WxH; default: the scene's");
  ref->add_option("--out", opt.out, "output directory");
  ref->add_option("--subdivide", opt.subdivide, "split each object's sphere into K")->check(CLI::Range(1, 4096));
  ref->add_option("--accel", opt.accel, "brute | bvh")->check(CLI::IsMember({"brute", "bvh"}));
  add_threads(ref);
  add_load_options(ref, opt.load, opt.split, opt.max_object_triangles);

  std::string compare_image, compare_reference;
  auto* compare = app.add_subcommand("compare", "print how far a frame is from a reference frame (JSON)");
  compare->add_option("IMAGE", compare_image, "frame_NNNN.exr to judge")->required();
  compare->add_option("REFERENCE", compare_reference, "frame_NNNN.exr of the same size to judge it against")->required();
  add_threads(compare);

  RenderOptions ro;
  auto* render = app.add_subcommand("render", "render with the timed SystemC model");
  render->add_option("SCENE", ro.scene, "scene file")->required();
  render->add_option("--arch", ro.arch_file, "architecture file (JSON, oprt-arch/1)");
  render->add_option("--ius", ro.ius, "number of intersection units");
  render->add_option("--frames", ro.frames, "N or A:B (inclusive); default: every frame");
  render->add_option("--level", ro.level, "at | lt | analytic")->check(CLI::IsMember({"at", "lt", "analytic"}));
  render->add_option("--quantum", ro.quantum, "temporal-decoupling quantum for lt, e.g. 1us");
  render->add_option("--balance", ro.balance, "paper | round_robin | sa_n | spatial | feedback | view")
      ->check(CLI::IsMember({"paper", "round_robin", "sa_n", "spatial", "feedback", "view"}));
  render->add_option("--locality", ro.locality,
                     "spatial, feedback: tight unit bounds (1) against balance (0); spatial's default 0.5");
  render->add_option("--subdivide", ro.subdivide, "split each object's sphere into K")->check(CLI::Range(1, 4096));
  render->add_option("--accel", ro.accel, "brute | bvh")->check(CLI::IsMember({"brute", "bvh"}));
  render->add_option("--top", ro.top, "flat | bvh: every sphere per ray, or a tree over each unit's spheres")
      ->check(CLI::IsMember({"flat", "bvh"}));
  render->add_option("--route", ro.route,
                     "broadcast | multicast | ordered: every unit gets every ray, or only those whose bound it "
                     "enters, or those nearest first, in waves")
      ->check(CLI::IsMember({"broadcast", "multicast", "ordered"}));
  render->add_option("--sram", ro.sram,
                     "object memory per unit in bytes (64K, 4M); a unit whose spheres need more uses it as a cache "
                     "in front of DRAM (0: no limit)");
  render->add_option("--kernel", ro.kernel, "moller | watertight")->check(CLI::IsMember({"moller", "watertight"}));
  render->add_option("--precision", ro.precision, "float | double")->check(CLI::IsMember({"float", "double"}));
  render->add_option("--iu", ro.iu, "serial | pipelined: the intersection unit's microarchitecture")
      ->check(CLI::IsMember({"serial", "pipelined"}));
  render->add_option("--tech", ro.tech, "technology table for area and energy (default: the built-in testbench/tech/65nm.json)");
  render->add_option("--resolution", ro.resolution, "WxH; default: the scene's");
  render->add_option("--out", ro.out, "output directory");
  render->add_option("--vcd", ro.vcd, "write a waveform trace to this file: VCD, or GTKWave's FST if it ends in .fst");
  render->add_option("--timeline", ro.timeline,
                     "write a transaction timeline to this file (Chrome trace-event JSON, for ui.perfetto.dev)");
  render->add_option("--trace-frames", ro.trace_frames, "trace only frames N or A:B (inclusive)");
  render->add_option("--trace-window", ro.trace_window, "trace only simulated times T0:T1, e.g. 10us:2ms");
  render->add_option("--trace-units", ro.trace_units, "trace only these intersection units, e.g. 0-3,7");
  render->add_option("--trace-signals", ro.trace_signals, "trace only these signal groups: state,fifo,bus,gpp,memory,stage");
  render->add_option("--trace-buffer", ro.trace_buffer,
                     "value changes the --vcd writer may hold ahead of simulation time before units running ahead "
                     "wait (default 131072, 16 bytes each)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32));
  render->add_flag("!--no-progress", ro.progress, "no progress bar");
  add_threads(render);
  add_load_options(render, ro.load, ro.split, ro.max_object_triangles);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 2;
  }
  install_stop_handlers();
  set_thread_count(threads);
  try {
    if (*info) return run_info(opt, info_arch);
    if (*ref) return run_reference(opt);
    if (*render) return run_render(ro);
    if (*compare) return run_compare(compare_image, compare_reference);
  } catch (const InputError& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 2;
  } catch (const Interrupted& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 128 + e.signal();
  } catch (const std::bad_alloc&) {
    std::cerr << "oprt: out of memory (a smaller --resolution, fewer --ius or a smaller scene needs less)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "oprt: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
