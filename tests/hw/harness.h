// Running the hardware model inside a test, as a platform does (examples/platform): a scene,
// an architecture, frames and a resolution in; the engine (model/hw/engine.h) driven by a
// host module of the test's own, one frame command after the other; every frame's image
// and the engine's figures out. Nothing from the testbench: a static assignment, no files.
#pragma once

#include "balance/policy.h"
#include "hw/engine.h"
#include "ref/frame_setup.h"
#include "ref/reference.h"
#include "scene/load.h"

#include <string>
#include <vector>

#include <systemc>

namespace oprt::test {

inline std::string scene_path(const std::string& name) { return std::string(OPRT_SOURCE_DIR) + "/scenes/" + name; }

struct FrameRange {
  int first = 0, last = 0;
};

struct Run {
  std::vector<SphereDef> spheres;
  Assignment assignment;
  std::vector<FrameImage> images;         // per frame of the range
  std::vector<timing::FrameRun> results;  // per frame: the engine's figures
};

template <typename T>
class Host : public sc_core::sc_module {
 public:
  SC_HAS_PROCESS(Host);
  Host(const sc_core::sc_module_name& name, hw::Engine<T>& engine, const Scene& scene, FrameRange frames, int w, int h,
       Run& out)
      : sc_module(name), engine_(engine), scene_(scene), frames_(frames), w_(w), h_(h), out_(out) {
    SC_THREAD(run);
  }

 private:
  void run() {
    engine_.setup();  // load the object memories before the first frame, outside it
    for (int f = frames_.first; f <= frames_.last; ++f) {
      engine_.reset_stats();
      FrameImage image(w_, h_);
      timing::FrameCommand cmd;
      cmd.frame = f;
      cmd.to_world = object_matrices(scene_, f);
      cmd.camera = scene_.camera->at(f);
      cmd.width = w_;
      cmd.height = h_;
      cmd.image = &image;
      engine_.run_frame(cmd);
      out_.results.push_back(engine_.figures());
      out_.images.push_back(std::move(image));
    }
    sc_core::sc_stop();
  }
  hw::Engine<T>& engine_;
  const Scene& scene_;
  const FrameRange frames_;
  const int w_, h_;
  Run& out_;
};

// The frames rendered by the engine (its own VCD writer when `vcd` names a file).
template <typename T>
Run simulate_scene(const Scene& scene, const Arch& arch, FrameRange frames, int width, int height,
                   VcdWriter* vcd = nullptr) {
  Run r;
  r.spheres = make_spheres(scene, arch.subdivide, split_rule_named(arch.split_rule),
                           object_split_named(arch.split, scene.source));  // as oprt render
  r.assignment = static_assignment(arch.balance, scene, r.spheres, units_for(r.spheres.size(), arch.ius));
  const SceneGeometry<T> g = build_geometry<T>(scene, r.spheres, arch.kernel, accel_named(arch.accel));
  hw::Engine<T> engine("engine", scene, g, arch, r.assignment.units(), vcd);
  engine.assign(r.assignment);
  Host<T> host("host", engine, scene, frames, width, height, r);
  sc_core::sc_start();
  return r;
}

}  // namespace oprt::test
