// What a run of the simulator needs in host memory, estimated before it loads or allocates
// anything: per ray of a frame in flight, per pixel, per cache line of a unit that is a cache,
// per vertex and triangle of the scene. The constants are fitted to measured peak memory and
// err on the high side (docs/reliability.md, "Memory refused up front"). Pure functions of the
// run's shape; testbench/memory_estimate.h compares the estimate with the memory the run may use.
#pragma once

#include "arch/arch.h"
#include "base/numbers.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

// What the estimate depends on.
struct RunShape {
  bool timed = true;  // render (the timed model); false: the reference renderer
  Level level = Level::at;
  std::uint64_t units = 1;   // intersection units (at most the spheres, at least one)
  bool bvh = false, double_precision = false;
  std::uint64_t sram_bytes = 0, line_bytes = 64;  // a unit that is a cache keeps a tag per line
  std::uint64_t trace_changes = 0;  // --vcd: the writer's buffer (--trace-buffer); 0: no waveform
  bool timeline = false;
};

// The rays a pixel's tree holds (the depth bound resolved: -1 the scene's).
std::uint64_t rays_per_pixel(const Scene& scene, int depth);

// Bytes per vertex and per triangle of the scene, in every form the run keeps.
std::uint64_t bytes_per_vertex(const RunShape& r);
std::uint64_t bytes_per_triangle(const RunShape& r);

struct MemoryEstimate {
  struct Part {
    std::string what;          // "rays and images of a frame: 65536 pixels x 3 rays at 687 bytes"
    std::string file, place;   // where the setting that makes it large is: "--resolution", "256x256"
    std::uint64_t bytes = 0;
  };
  std::vector<Part> parts;
  std::uint64_t total() const;
};

// Everything but the scene's geometry; the image's part when its size is known (pixels > 0),
// set at `image` ("--resolution", or the scene file's "/image").
MemoryEstimate memory_estimate(const RunShape& r, std::uint64_t pixels, std::uint64_t rays_per_pixel,
                               const NumberSource& image = {});
// Adds the scene's geometry.
void add_geometry(MemoryEstimate& e, const RunShape& r, std::uint64_t vertices, std::uint64_t triangles,
                  const std::string& scene_file);

}  // namespace oprt
