// What a run will need (the estimate: cost/host_memory.h), refused when it is more than the
// run may use: --max-memory, else the memory available (the kernel's MemAvailable, and what
// the process's cgroup still allows). The scene's meshes are charged while the scene loads,
// before each is made (scene/load.h MeshBudget); the rest (the rays and images of a frame,
// cache tags, trace buffers) once the scene's size and resolution are known, before the
// engine is built.
#pragma once

#include "cost/host_memory.h"
#include "base/numbers.h"

#include <cstdint>
#include <optional>
#include <string>

namespace oprt {

struct MemoryLimit {
  std::uint64_t bytes = 0;  // 0: no limit known
  std::string source;       // for messages: "--max-memory 2G", "the memory available (...)"
  NumberSource set_by;      // where a refusal that names no larger setting points: --max-memory, or "memory"
};

// --max-memory (a byte count) if given, else what the machine has available.
MemoryLimit memory_limit(const std::optional<std::string>& max_memory);

// Throws InputError naming the largest part's file and place, the estimate and the limit.
void refuse_if_over(const MemoryEstimate& e, const MemoryLimit& limit);

// Sets scene_limits (scene/load.h) so that the loaders refuse a mesh that would not fit
// beside `reserved` (what the rest of the run needs).
void limit_scene_memory(const MemoryLimit& limit, const RunShape& r, const MemoryEstimate& reserved);

// The last estimate a run made, for the message if memory runs out nonetheless.
const std::string& last_memory_estimate();

}  // namespace oprt
