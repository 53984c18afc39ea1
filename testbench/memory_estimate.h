// What a run will need, estimated before it loads or allocates anything, and refused when it
// is more than the run may use: --max-memory, else the memory available (the kernel's
// MemAvailable, and what the process's cgroup still allows). The scene's meshes are charged
// while the scene loads, before each is made (scene/load.h MeshBudget); the rest (the rays and
// images of a frame, cache tags, trace buffers) once the scene's size and resolution are known,
// before the engine is built. The constants are fitted to measured peak memory and err on the
// high side (docs/reliability.md, "Memory refused up front").
#pragma once

#include "arch/arch.h"
#include "scene/numbers.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace oprt {

struct MemoryLimit {
  std::uint64_t bytes = 0;  // 0: no limit known
  std::string source;       // for messages: "--max-memory 2G", "the memory available (...)"
  NumberSource set_by;      // where a refusal that names no larger setting points: --max-memory, or "memory"
};

// --max-memory (a byte count) if given, else what the machine has available.
MemoryLimit memory_limit(const std::optional<std::string>& max_memory);

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

// Throws InputError naming the largest part's file and place, the estimate and the limit.
void refuse_if_over(const MemoryEstimate& e, const MemoryLimit& limit);

// Sets scene_limits (scene/load.h) so that the loaders refuse a mesh that would not fit
// beside `reserved` (what the rest of the run needs).
void limit_scene_memory(const MemoryLimit& limit, const RunShape& r, const MemoryEstimate& reserved);

// The last estimate a run made, for the message if memory runs out nonetheless.
const std::string& last_memory_estimate();

}  // namespace oprt
