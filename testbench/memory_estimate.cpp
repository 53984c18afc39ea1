#include "memory_estimate.h"

#include "base/error.h"
#include "scene/load.h"
#include "base/numbers.h"

#include <fstream>
#include <sstream>

namespace oprt {

namespace {

std::string g_last;

// /proc/meminfo's MemAvailable, in bytes (0 if unknown).
std::uint64_t mem_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kb;
  std::string unit;
  while (in >> key >> kb) {
    std::getline(in, unit);
    if (key == "MemAvailable:") return kb * 1024;
  }
  return 0;
}

// What the cgroup (v2) of this process still allows, or 0 if it sets no limit.
std::uint64_t cgroup_room() {
  std::ifstream self("/proc/self/cgroup");
  std::string line, path;
  while (std::getline(self, line))
    if (line.rfind("0::", 0) == 0) path = line.substr(3);
  const std::string dir = "/sys/fs/cgroup" + path;
  std::ifstream max(dir + "/memory.max"), current(dir + "/memory.current");
  std::string m;
  std::uint64_t c = 0;
  if (!(max >> m) || m == "max" || !(current >> c)) return 0;
  const std::uint64_t limit = std::stoull(m);
  return limit > c ? limit - c : 1;
}

}  // namespace

MemoryLimit memory_limit(const std::optional<std::string>& max_memory) {
  if (max_memory) {
    const std::uint64_t b = parse_bytes(*max_memory, ~std::uint64_t{0}, {"--max-memory", *max_memory});
    return {b, "--max-memory " + *max_memory, {"--max-memory", *max_memory}};
  }
  const std::uint64_t available = mem_available(), room = cgroup_room();
  if (room && (!available || room < available))
    return {room, "what this process's cgroup still allows (memory.max); --max-memory sets another limit", {"memory", ""}};
  return {available, "the memory available, MemAvailable in /proc/meminfo; --max-memory sets another limit",
          {"memory", ""}};
}

void refuse_if_over(const MemoryEstimate& e, const MemoryLimit& limit) {
  std::ostringstream s;
  s << "about " << byte_count_text(e.total()) << " (" << e.total() << " bytes):";
  const MemoryEstimate::Part* largest = nullptr;
  for (const MemoryEstimate::Part& p : e.parts) {
    s << (&p == &e.parts.front() ? " " : "; ") << p.what << " " << byte_count_text(p.bytes);
    if (!p.file.empty() && (!largest || p.bytes > largest->bytes)) largest = &p;
  }
  g_last = s.str();
  if (limit.bytes == 0 || e.total() <= limit.bytes) return;
  throw InputError(largest ? largest->file : limit.set_by.file, largest ? largest->place : limit.set_by.place,
                   "the run would need " + g_last + ": more than the " + byte_count_text(limit.bytes) +
                       " it may use (" + limit.source + ")");
}

void limit_scene_memory(const MemoryLimit& limit, const RunShape& r, const MemoryEstimate& reserved) {
  scene_limits.memory_limit = limit.bytes;
  scene_limits.memory_limit_source = limit.source;
  scene_limits.memory_reserved = reserved.total();
  scene_limits.bytes_per_vertex = bytes_per_vertex(r);
  scene_limits.bytes_per_triangle = bytes_per_triangle(r);
}

const std::string& last_memory_estimate() { return g_last; }

}  // namespace oprt
