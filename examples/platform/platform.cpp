// A platform of one's own around oprt's engine: its sc_main instantiates the engine (every
// binding inside it: hw/engine.h) for a scene and an architecture file, binds the engine's
// memory port to a memory of the platform's (LineMemory, below: a DRAM with a fixed latency
// that serves cache line fills), renders frames and writes their images.
//
//   platform SCENE ARCH.json WxH OUT_DIR [FRAME]
//
// The architecture file is oprt's (docs/architecture-format.md); the platform sets
// memory.dram.path to "external" itself, so every object-memory miss comes here (with
// memory.sram_bytes small enough that the units' spheres do not fit: their memories are then
// caches). It prints how many fills its memory served. Built against the installed package:
// CMakeLists.txt here (find_package(oprt)), or
//   g++ platform.cpp $(pkg-config --cflags --libs oprt) -o platform
#include "arch/arch.h"
#include "balance/policy.h"
#include "balance/spheres.h"
#include "hw/engine.h"
#include "ref/frame_setup.h"
#include "ref/image.h"
#include "ref/scene_geometry.h"
#include "base/error.h"
#include "scene/load.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_target_socket.h>
#include <tlm_utils/tlm_quantumkeeper.h>

namespace {

using namespace sc_core;

// The platform's memory: every line fill takes `latency` and is served whole. It checks what
// the port promises (docs/architecture-format.md, "The memory port"): reads, one line each,
// inside the DRAM region, from a unit the engine has.
class LineMemory : public sc_module {
 public:
  tlm_utils::simple_target_socket<LineMemory> in{"in"};

  LineMemory(const sc_module_name& name, sc_time latency, unsigned line_bytes, std::size_t units)
      : sc_module(name), latency_(latency), line_bytes_(line_bytes), units_(units) {
    in.register_b_transport(this, &LineMemory::b_transport);
  }
  std::uint64_t fills() const { return fills_; }
  std::uint64_t bytes() const { return bytes_; }

 private:
  void b_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
    const auto* f = p.get_extension<oprt::hw::FillExtension>();
    const std::uint64_t a = p.get_address();
    if (p.get_command() != tlm::TLM_READ_COMMAND || p.get_data_length() != line_bytes_ || !f || f->unit >= units_ ||
        a < oprt::hw::addr::dram_base || a - oprt::hw::addr::dram_base >= oprt::hw::addr::dram_size ||
        (a - oprt::hw::addr::dram_base) % line_bytes_ != 0) {
      p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
      return;
    }
    delay += latency_;  // LT: the line is there when the returned delay has passed
    ++fills_;
    bytes_ += p.get_data_length();
    p.set_response_status(tlm::TLM_OK_RESPONSE);
  }

  const sc_time latency_;
  const unsigned line_bytes_;
  const std::size_t units_;
  std::uint64_t fills_ = 0, bytes_ = 0;
};

// The platform's host: one thread that loads the object memories, then runs each frame.
template <typename T>
class Host : public sc_module {
 public:
  SC_HAS_PROCESS(Host);
  Host(const sc_module_name& name, oprt::hw::Engine<T>& engine, const oprt::Scene& scene, int frame, int w, int h)
      : sc_module(name), image(w, h), engine_(engine), scene_(scene), frame_(frame) {
    SC_THREAD(run);
  }
  oprt::FrameImage image;
  bool done = false;

 private:
  void run() {
    engine_.setup();  // load the object memories (no frame's time)
    oprt::timing::FrameCommand cmd;
    cmd.frame = frame_;
    cmd.to_world = oprt::object_matrices(scene_, frame_);
    cmd.camera = scene_.camera->at(frame_);
    cmd.width = image.width;
    cmd.height = image.height;
    cmd.image = &image;
    engine_.run_frame(cmd);
    done = true;
    sc_stop();
  }
  oprt::hw::Engine<T>& engine_;
  const oprt::Scene& scene_;
  const int frame_;
};

template <typename T>
int run(const oprt::Scene& scene, const oprt::Arch& arch, int frame, int w, int h, const std::string& out) {
  using namespace oprt;
  const std::vector<SphereDef> spheres =
      make_spheres(scene, arch.subdivide, split_rule_named(arch.split_rule), object_split_named(arch.split, scene.source));
  const std::size_t units = units_for(spheres.size(), static_cast<std::size_t>(arch.ius));
  const SceneGeometry<T> geometry = build_geometry<T>(scene, spheres, arch.kernel, accel_named(arch.accel));
  // A policy's assignment before any frame is measured (oprt render re-balances per frame
  // for "feedback" and "view"; the image is the same whatever the assignment).
  const Assignment assignment = initial_assignment(arch.balance, arch.locality, scene, spheres, units);
  if (arch.level == Level::lt)
    tlm_utils::tlm_quantumkeeper::set_global_quantum(sc_time(arch.quantum_ns, SC_NS));

  hw::Engine<T> engine("engine", scene, geometry, arch, units, nullptr);
  LineMemory memory("memory", sc_time(arch.cycle_ns() * 50, SC_NS),
                    static_cast<unsigned>(arch.memory.cache.line_bytes), units);
  engine.mem.bind(memory.in);  // the platform's memory behind every object memory
  engine.assign(assignment);
  Host<T> host("host", engine, scene, frame, w, h);
  sc_start();
  if (!host.done) {
    std::fprintf(stderr, "platform: the frame did not complete\n");
    return 1;
  }
  std::filesystem::create_directories(out);
  write_exr(out + "/" + frame_name(frame, "exr"), host.image);
  write_png(out + "/" + frame_name(frame, "png"), host.image);
  std::printf("platform: frame %d, %zu units, %s written to %s; memory served %llu fills (%llu bytes), "
              "simulated time %s\n",
              frame, units, frame_name(frame, "exr").c_str(), out.c_str(),
              static_cast<unsigned long long>(memory.fills()), static_cast<unsigned long long>(memory.bytes()),
              sc_time_stamp().to_string().c_str());
  return 0;
}

}  // namespace

int sc_main(int argc, char* argv[]) {
  if (argc < 5 || argc > 6) {
    std::fprintf(stderr, "usage: platform SCENE ARCH.json WxH OUT_DIR [FRAME]\n");
    return 2;
  }
  // SystemC's errors end the run through the catch below; its "simulation stopped" note is quiet.
  sc_core::sc_report_handler::set_actions(sc_core::SC_FATAL, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions("/OSCI/SystemC", sc_core::SC_INFO, sc_core::SC_DO_NOTHING);
  try {
    const oprt::Scene scene = oprt::load_scene(argv[1]);
    oprt::Arch arch = oprt::load_arch(argv[2]);
    int w = 0, h = 0;
    char x = 0;
    if (std::sscanf(argv[3], "%d%c%d", &w, &x, &h) != 3 || x != 'x' || w <= 0 || h <= 0)
      throw oprt::InputError("WxH", argv[3], "expected a resolution such as 32x32");
    const int frame = argc == 6 ? std::stoi(argv[5]) : 0;
    if (arch.level == oprt::Level::analytic)
      throw oprt::InputError(argv[2], "/level", "the platform simulates (at or lt): the analytic level has no sockets");
    arch.memory.dram.path = oprt::DramPath::external;  // every fill through the engine's memory port
    return arch.precision == "double" ? run<double>(scene, arch, frame, w, h, argv[4])
                                      : run<float>(scene, arch, frame, w, h, argv[4]);
  } catch (const oprt::InputError& e) {
    std::fprintf(stderr, "platform: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "platform: %s\n", e.what());
    return 1;
  }
}
