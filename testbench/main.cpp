// oprt: the command line of the object-parallel ray-tracing engine model.
//   oprt render SCENE ...     the timed SystemC model
//   oprt reference SCENE ...  the untimed functional reference
//   oprt info SCENE ...       scene, spheres and their assignment
//   oprt compare A.exr B.exr  how far frame A is from reference frame B (JSON)
//   oprt batch SCENE --archs FILE.jsonl --out DIR   many analytic renders of one scene
// Any bad input ends with one message "oprt: FILE: PLACE: PROBLEM" and exit status 2.
#include "batch.h"
#include "commands.h"
#include "memory_estimate.h"
#include "render.h"
#include "ref/parallel.h"
#include "ref/stop.h"
#include "base/error.h"
#include "base/numbers.h"

#include <CLI/CLI.hpp>

#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <unistd.h>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

// Numbers on the command line are taken as text and read by the one parser of their kind
// (base/numbers.h), after CLI11 has parsed the line, so that every message states the
// real limit. Each numeric option registers how to convert its text here.
class Numbers {
 public:
  // A count in [lo, hi] into `set`.
  void count(CLI::App* sub, const std::string& name, std::uint64_t lo, std::uint64_t hi, const std::string& help,
             std::function<void(std::uint64_t)> set) {
    auto text = std::make_shared<std::string>();
    CLI::Option* o = sub->add_option(name, *text, help + " (" + std::to_string(lo) + " to " + std::to_string(hi) + ")");
    convert_.push_back([o, text, name, lo, hi, set] {
      if (o->count()) set(oprt::parse_count(*text, lo, hi, {name, *text}));
    });
  }
  void run() const {
    for (const auto& c : convert_) c();
  }

 private:
  std::vector<std::function<void()>> convert_;
};

}  // namespace

namespace {

// A frame's trace is hundreds of megabytes written once: on 4 KiB pages the kernel's page
// faults were a fifth of the analytic level's time (perf). glibc's malloc backs its memory
// with transparent huge pages when the tunable glibc.malloc.hugetlb=1 is set, and tunables are
// read only when a process starts: set it and start again, once (OPRT_SMALL_PAGES=1: not).
// Measured on the room at 256x256 (docs/results.md, "What the options cost the simulator").
void start_on_huge_pages(char** argv) {
  if (std::getenv("OPRT_SMALL_PAGES")) return;
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")) return;  // set already (by us or the user)
  const std::string value = tunables ? std::string(tunables) + ":glibc.malloc.hugetlb=1" : "glibc.malloc.hugetlb=1";
  if (::setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);  // returns only if it failed: then go on as we are
}

}  // namespace

namespace {

// The command line: one subcommand per command, each with its options and the numbers they
// take (Numbers), read into the options each command runs with.
struct CommandLine {
  CLI::App app{"oprt: a SystemC/TLM-2.0 model of an object-parallel ray-tracing engine for animated scenes"};
  oprt::CommonOptions opt;
  oprt::RenderOptions info_arch;  // with any of --arch, --ius, --balance, --locality: the assignment too
  oprt::RenderOptions ro;
  oprt::BatchOptions batch_opts;
  std::string compare_image, compare_reference;
  Numbers numbers;
  int threads = 0;  // 0: every core
  CLI::App *info = nullptr, *ref = nullptr, *compare = nullptr, *render = nullptr, *batch = nullptr;
  const std::string max_memory_help =
      "refuse a run whose estimated memory is more than BYTES (64M, 2G, 1.5T; default: the memory available)";

  CommandLine() {
    app.require_subcommand(1);
    add_info();
    add_reference();
    add_compare();
    add_render();
    add_batch();
  }

  void add_threads(CLI::App* sub) {
    numbers.count(sub, "--threads", 1, 4096, "threads for the functional work (default: every core)",
                  [this](std::uint64_t n) { threads = static_cast<int>(n); });
  }
  template <typename Target>  // int, or std::optional<int> where absent means "as the file says"
  void add_subdivide(CLI::App* sub, Target& target) {
    numbers.count(sub, "--subdivide", 1, 4096, "split each object's sphere into K",
                  [&target](std::uint64_t n) { target = static_cast<int>(n); });
  }
  void add_scene(CLI::App* sub) { sub->add_option("SCENE", opt.scene, "scene file (.json, .aff, .gltf, .glb)")->required(); }
  // How a BART .aff scene becomes objects (docs/aff.md).
  void add_load_options(CLI::App* sub, oprt::LoadOptions& load, std::string& split,
                        std::optional<std::size_t>& max_object_triangles) {
    sub->add_option("--split", split,
                    "count | extent: how objects become spheres (default: extent for .aff and glTF, count for .json)")
        ->check(CLI::IsMember({"count", "extent"}));
    numbers.count(sub, "--max-object-triangles", 0, std::uint64_t{1} << 25,
                  "AFF: split static and rigid groups into objects of at most N triangles (0: never; default 4096 "
                  "under --split count, 0 under extent)",
                  [&max_object_triangles](std::uint64_t n) { max_object_triangles = n; });
    numbers.count(sub, "--tessellation", 4, 4096, "AFF: spheres get N segments and N/2 rings, cones N segments (default 16)",
                  [&load](std::uint64_t n) {
                    load.aff.sphere_segments = load.aff.cone_segments = static_cast<unsigned>(n);
                    load.aff.sphere_rings = static_cast<unsigned>(n / 2);
                  });
  }
  void add_info();
  void add_reference();
  void add_compare();
  void add_render();
  void add_render_outputs();
  void add_batch();
};

void CommandLine::add_batch() {
  batch = app.add_subcommand("batch", "render one scene for many architectures in one process (analytic level)");
  batch->add_option("SCENE", batch_opts.scene, "scene file")->required();
  batch->add_option("--archs", batch_opts.archs,
                    "JSON lines, each {\"args\": [...]}: the options of one oprt render (without SCENE and --out)")
      ->required();
  batch->add_option("--out", batch_opts.out, "output folder: line i renders into DIR/i (stats.json, status.json)")
      ->required();
  add_threads(batch);
}

// One line of a batch: `oprt render SCENE ARGS`, parsed by render's own command line.
oprt::RenderOptions parse_render_line(const std::vector<std::string>& args, const std::string& scene) {
  CommandLine c;
  std::vector<std::string> words = {"oprt", "render", scene};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  try {
    c.app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::CallForHelp&) {
    throw oprt::LineRefused("--help: not an option of a batch line");
  } catch (const CLI::ParseError& e) {
    throw oprt::LineRefused(e.what());
  }
  c.numbers.run();
  return c.ro;
}

void CommandLine::add_info() {
  info = app.add_subcommand("info", "print the scene, its bounding spheres and their SA x N");
  info->add_option("SCENE", opt.scene, "scene file (.json, .aff, .gltf, .glb)");
  info->add_flag("--schedules", opt.schedules, "print the IU operations' cycle schedules");
  add_subdivide(info, info_arch.subdivide);
  info->add_option("--arch", info_arch.arch_file, "architecture file (JSON, oprt-arch/1)");
  numbers.count(info, "--ius", 1, 65536, "number of intersection units",
                [this](std::uint64_t n) { info_arch.ius = static_cast<int>(n); });
  info->add_option("--balance", info_arch.balance, "paper | round_robin | sa_n | spatial | feedback | view (frame 0)")
      ->check(CLI::IsMember({"paper", "round_robin", "sa_n", "spatial", "feedback", "view"}));
  info->add_option("--locality", info_arch.locality, "spatial, feedback: tight unit bounds (1) against balance (0)");
  info->add_option("--accel", info_arch.accel, "brute | bvh: what the sa_n cost estimate assumes inside a sphere")
      ->check(CLI::IsMember({"brute", "bvh"}));
  add_load_options(info, opt.load, opt.split, opt.max_object_triangles);
}

void CommandLine::add_reference() {
  ref = app.add_subcommand("reference", "render with the untimed functional reference");
  add_scene(ref);
  ref->add_option("--precision", opt.precision, "float | double")->check(CLI::IsMember({"float", "double"}));
  ref->add_option("--kernel", opt.kernel, "moller | watertight")->check(CLI::IsMember({"moller", "watertight"}));
  ref->add_option("--frames", opt.frames, "N or A:B (inclusive); default: every frame");
  numbers.count(ref, "--depth", 0, oprt::kMaxDepth,
                "bounces of reflection and refraction rays (default: the scene's, else 5; 0: primary and shadow only)",
                [this](std::uint64_t n) { opt.depth = static_cast<int>(n); });
  ref->add_option("--resolution", opt.resolution, "WxH; default: the scene's");
  ref->add_option("--out", opt.out, "output directory");
  add_subdivide(ref, opt.subdivide);
  ref->add_option("--accel", opt.accel, "brute | bvh")->check(CLI::IsMember({"brute", "bvh"}));
  ref->add_option("--max-memory", opt.max_memory, max_memory_help);
  add_threads(ref);
  add_load_options(ref, opt.load, opt.split, opt.max_object_triangles);
}

void CommandLine::add_compare() {
  compare = app.add_subcommand("compare", "print how far a frame is from a reference frame (JSON)");
  compare->add_option("IMAGE", compare_image, "frame_NNNN.exr to judge")->required();
  compare->add_option("REFERENCE", compare_reference, "frame_NNNN.exr of the same size to judge it against")->required();
  add_threads(compare);
}

void CommandLine::add_render() {
  render = app.add_subcommand("render", "render with the timed SystemC model");
  render->add_option("SCENE", ro.scene, "scene file")->required();
  render->add_option("--arch", ro.arch_file, "architecture file (JSON, oprt-arch/1)");
  numbers.count(render, "--ius", 1, 65536, "number of intersection units",
                [this](std::uint64_t n) { ro.ius = static_cast<int>(n); });
  render->add_option("--frames", ro.frames, "N or A:B (inclusive); default: every frame");
  numbers.count(render, "--depth", 0, oprt::kMaxDepth,
                "bounces of reflection and refraction rays (default: the architecture's gpp.depth, else the scene's, "
                "else 5; 0: primary and shadow rays only)",
                [this](std::uint64_t n) { ro.depth = static_cast<int>(n); });
  render->add_option("--level", ro.level, "at | lt | analytic")->check(CLI::IsMember({"at", "lt", "analytic"}));
  render->add_option("--quantum", ro.quantum, "temporal-decoupling quantum for lt, e.g. 1us");
  render->add_option("--balance", ro.balance, "paper | round_robin | sa_n | spatial | feedback | view")
      ->check(CLI::IsMember({"paper", "round_robin", "sa_n", "spatial", "feedback", "view"}));
  render->add_option("--locality", ro.locality,
                     "spatial, feedback: tight unit bounds (1) against balance (0); spatial's default 0.5");
  render->add_option("--replicate", ro.replicate,
                     "auto | N | off: copies of the hottest spheres on several units, each ray sent to one copy "
                     "(auto: as many as balance the units within their memory; N: at most N copies of a sphere)");
  add_subdivide(render, ro.subdivide);
  render->add_option("--accel", ro.accel, "brute | bvh")->check(CLI::IsMember({"brute", "bvh"}));
  render->add_option("--top", ro.top, "flat | bvh: every sphere per ray, or a tree over each unit's spheres")
      ->check(CLI::IsMember({"flat", "bvh"}));
  render->add_option("--route", ro.route,
                     "broadcast | multicast | ordered: every unit gets every ray, or only those whose bound it "
                     "enters, or those nearest first, in waves")
      ->check(CLI::IsMember({"broadcast", "multicast", "ordered"}));
  render->add_option("--sram", ro.sram,
                     "object memory per unit in bytes (64K, 4M, 1G; at most 1T); a unit whose spheres need more uses "
                     "it as a cache in front of DRAM (0: no limit)");
  render->add_option("--kernel", ro.kernel, "moller | watertight")->check(CLI::IsMember({"moller", "watertight"}));
  render->add_option("--precision", ro.precision, "float | double")->check(CLI::IsMember({"float", "double"}));
  render->add_option("--iu", ro.iu, "serial | pipelined: the intersection unit's microarchitecture")
      ->check(CLI::IsMember({"serial", "pipelined"}));
  render->add_option("--tech", ro.tech, "technology table for area and energy (default: the built-in testbench/tech/65nm.json)");
  render->add_option("--sample", ro.sample,
                     "1/N (1/4, 1/16, 1/64; or 0.0625): trace one pixel in each block of N and estimate the full "
                     "frame's figures with 95 % intervals (stats.json \"sample\"); 1: every pixel");
  numbers.count(render, "--seed", 0, ~std::uint64_t{0}, "which pixel of each block --sample traces (default 0)",
                [this](std::uint64_t n) { ro.seed = n; });
  render->add_option("--sample-fifos", ro.sample_fifos,
                     "scaled | kept: --sample times ray FIFOs that hold the same stretch of the screen as the full "
                     "frame's (default), or the architecture's")
      ->check(CLI::IsMember({"scaled", "kept"}));
  add_render_outputs();
}

// What a render writes, and the tracing, progress and checking options.
void CommandLine::add_render_outputs() {
  render->add_option("--resolution", ro.resolution, "WxH; default: the scene's");
  render->add_option("--out", ro.out, "output directory");
  render->add_option("--vcd", ro.vcd, "write a waveform trace to this file: VCD, or GTKWave's FST if it ends in .fst");
  render->add_option("--timeline", ro.timeline,
                     "write a transaction timeline to this file (Chrome trace-event JSON, for ui.perfetto.dev)");
  render->add_option("--trace-frames", ro.trace_frames, "trace only frames N or A:B (inclusive)");
  render->add_option("--trace-window", ro.trace_window, "trace only simulated times T0:T1, e.g. 10us:2ms");
  render->add_option("--trace-units", ro.trace_units, "trace only these intersection units, e.g. 0-3,7");
  render->add_option("--trace-signals", ro.trace_signals, "trace only these signal groups: state,fifo,bus,gpp,memory,stage");
  numbers.count(render, "--trace-buffer", 1, std::uint64_t{1} << 32,
                "value changes the --vcd writer may hold ahead of simulation time before units running ahead wait "
                "(default 131072, 16 bytes each)",
                [this](std::uint64_t n) { ro.trace_buffer = static_cast<std::size_t>(n); });
  render->add_option("--max-memory", ro.max_memory, max_memory_help);
  render->add_flag("!--no-progress", ro.progress, "no progress bar");
  render->add_flag("--check", ro.check,
                   "check everything a render checks (files, numbers, outputs, memory), print the memory estimate, "
                   "and render nothing (exit 0, or 2 with the message)");
  add_threads(render);
  add_load_options(render, ro.load, ro.split, ro.max_object_triangles);
}

}  // namespace

int main(int argc, char** argv) {
  start_on_huge_pages(argv);
  using namespace oprt;
  CommandLine c;
  try {
    c.app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return c.app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 2;
  }
  install_stop_handlers();
  try {
    c.numbers.run();
    set_thread_count(c.threads);
    if (*c.info) return run_info(c.opt, c.info_arch);
    if (*c.ref) return run_reference(c.opt);
    if (*c.render) return run_render(c.ro);
    if (*c.compare) return run_compare(c.compare_image, c.compare_reference);
    if (*c.batch)
      return run_batch(c.batch_opts, [&c](const std::vector<std::string>& args) {
        return parse_render_line(args, c.batch_opts.scene);
      });
  } catch (const InputError& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 2;
  } catch (const Interrupted& e) {
    std::cerr << "oprt: " << e.what() << "\n";
    return 128 + e.signal();
  } catch (const std::bad_alloc&) {
    const std::string& estimate = last_memory_estimate();
    std::cerr << "oprt: out of memory"
              << (estimate.empty() ? std::string(" before the run's memory was estimated")
                                   : " although the run was estimated to need " + estimate)
              << " (docs/reliability.md; --max-memory makes the estimate's check stricter)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "oprt: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
