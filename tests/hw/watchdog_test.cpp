// The deadlock watchdog. The engine's wiring cannot deadlock (the GPP writes a ray only when
// every FIFO has room), so this test builds what only a test can: the real modules wired
// wrongly. Unit 1 reads unit 0's FIFO and nothing reads FIFO 1. Every ray then gets one
// answer where the GPP waits for two, FIFO 1 fills up, and the GPP waits for room in it
// forever: the kernel runs out of events with the frame unfinished.
#include "harness.h"
#include "hw/bus.h"
#include "hw/gpp.h"
#include "hw/extensions.h"
#include "hw/serial_unit.h"
#include "hw/object_memory.h"
#include "hw/ray_fifo.h"
#include "hw/watchdog.h"

#include <catch2/catch.hpp>

#include <tlm_utils/simple_initiator_socket.h>

using namespace oprt;
using namespace sc_core;

namespace {

struct Miswired : sc_module {
  FunctionalFrame<float> frame;
  hw::Gpp<float> gpp;
  hw::Bus bus;
  hw::RayFifo fifo0, fifo1;
  hw::ObjectMemory memory0, memory1;
  hw::SerialUnit<float> iu0, iu1;
  tlm_utils::simple_initiator_socket<Miswired> host{"host"};
  FrameImage image{8, 8};
  bool frame_done = false;

  SC_HAS_PROCESS(Miswired);
  Miswired(const sc_module_name& n, const Scene& scene, const SceneGeometry<float>& g, const Arch& arch)
      : sc_module(n),
        gpp("gpp", scene, g, arch, frame, nullptr),
        bus("bus", arch, false, nullptr),
        fifo0("fifo0", arch.fifo_depth, nullptr),
        fifo1("fifo1", arch.fifo_depth, nullptr),
        memory0("memory0", 0, arch, g.sphere_count(), nullptr),
        memory1("memory1", 1, arch, g.sphere_count(), nullptr),
        iu0("iu0", 0, arch, g, frame, nullptr),
        iu1("iu1", 1, arch, g, frame, nullptr) {
    host.bind(gpp.host);
    gpp.bus.bind(bus.in);
    bus.out.bind(gpp.hits);
    bus.map(hw::addr::gpp_hits, hw::addr::region_size, {0});
    hw::IntersectionUnit<float>* units[2] = {&iu0, &iu1};
    hw::RayFifo* fifos[2] = {&fifo0, &fifo1};
    hw::ObjectMemory* memories[2] = {&memory0, &memory1};
    for (int i = 0; i < 2; ++i) {
      units[i]->bus.bind(bus.in);
      units[i]->mem.bind(memories[i]->read);
      gpp.fifos.bind(*fifos[i]);
      bus.out.bind(units[i]->cfg);
      bus.out.bind(memories[i]->load);
      bus.out.bind(fifos[i]->in);
      const std::uint64_t w = hw::addr::iu_window(i);
      bus.map(w + hw::addr::iu_config, hw::addr::iu_memory - hw::addr::iu_config, {1 + 3 * i});
      bus.map(w + hw::addr::iu_memory, hw::addr::iu_ray_fifo - hw::addr::iu_memory, {2 + 3 * i});
      bus.map(w + hw::addr::iu_ray_fifo, hw::addr::iu_stride - hw::addr::iu_ray_fifo, {3 + 3 * i});
    }
    bus.map(hw::addr::broadcast_rays, hw::addr::region_size, {3, 6});
    iu0.fifo.bind(fifo0);
    iu1.fifo.bind(fifo0);  // the fault
    SC_THREAD(drive);
  }

  void send(timing::FrameCommand& cmd) {
    tlm::tlm_generic_payload p;
    unsigned char bytes[1] = {};
    hw::prepare<hw::FrameExtension>(p, tlm::TLM_WRITE_COMMAND, 0, bytes, 1).command = &cmd;
    sc_time d = SC_ZERO_TIME;
    host->b_transport(p, d);
  }

  void drive() {
    timing::FrameCommand setup;
    setup.setup_only = true;
    send(setup);
    timing::FrameCommand cmd = frame_command();
    send(cmd);
    frame_done = true;
  }

  timing::FrameCommand frame_command();
  const Scene* scene = nullptr;
};

timing::FrameCommand Miswired::frame_command() {
  timing::FrameCommand cmd;
  cmd.frame = 0;
  cmd.to_world = object_matrices(*scene, 0);
  cmd.camera = scene->camera->at(0);
  cmd.width = image.width;
  cmd.height = image.height;
  cmd.image = &image;
  return cmd;
}

}  // namespace

TEST_CASE("watchdog: a deadlocked frame ends with the blocked units and their FIFOs named", "[watchdog]") {
  const Scene scene = load_scene(std::string(OPRT_SOURCE_DIR) + "/tests/data/scenes/small.json");
  Arch arch;
  arch.fifo_depth = 2;
  const auto spheres = make_spheres(scene, 1);
  REQUIRE(spheres.size() >= 2);
  const SceneGeometry<float> g = build_geometry<float>(scene, spheres);
  Miswired top("top", scene, g, arch);
  top.scene = &scene;
  std::vector<std::vector<std::uint32_t>> assignment(2);
  for (std::uint32_t s = 0; s < spheres.size(); ++s) assignment[s % 2].push_back(s);
  top.gpp.set_assignment(assignment);

  sc_start();  // returns: the kernel has no events left

  CHECK_FALSE(top.frame_done);
  CHECK_FALSE(sc_pending_activity());
  std::string report;
  try {
    hw::check_deadlock("frame 0 is unfinished");
    FAIL("no deadlock reported");
  } catch (const hw::Deadlock& e) {
    report = e.what();
  }
  INFO(report);
  CHECK_THAT(report, Catch::StartsWith("deadlock at "));
  CHECK_THAT(report, Catch::Contains("frame 0 is unfinished"));
  // Nothing reads FIFO 1: it filled up, and the GPP waits for room in it.
  CHECK_THAT(report, Catch::Contains("top.fifo1: holds 2 rays of 2 (full)"));
  CHECK_THAT(report, Catch::Contains("waiting for answers or for room in top.fifo1 (holds 2 rays of 2 (full)"));
  // Both units took every ray of FIFO 0 between them, so each ray has one answer of two.
  CHECK_THAT(report, Catch::Contains("top.fifo0: holds 0 rays of 2"));
  CHECK_THAT(report, Catch::Contains("top.iu0: waiting for a ray; its FIFO top.fifo0 holds 0 rays of 2"));
  CHECK_THAT(report, Catch::Contains("top.iu1: waiting for a ray; its FIFO top.fifo0 holds 0 rays of 2"));
  CHECK_THAT(report, Catch::Contains("has 1 of 2 answers"));
  // Nothing is reported while the model works: a finished run has no unfinished work.
  CHECK_NOTHROW(hw::check_deadlock(""));
}
