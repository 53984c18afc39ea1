#include "memory_estimate.h"

#include "scene/error.h"
#include "scene/load.h"
#include "scene/numbers.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace oprt {

namespace {

// The constants, fitted to the peak resident memory of `oprt render` and `oprt reference`
// (docs/reliability.md has the measurements), rounded up.
constexpr std::uint64_t kBase = 32ull << 20;  // the process: libraries, SystemC, thread pools
// Per ray of a frame in flight at once (every primary ray is issued before the units catch
// up): its record, its answers, its functional trace and, per unit, its FIFO entry and work.
constexpr std::uint64_t kRayTimed = 175, kRayTimedPerUnit = 16;
constexpr std::uint64_t kRayAnalytic = 160, kRayAnalyticPerUnit = 8;
constexpr std::uint64_t kPixelReference = 48;  // the reference: the image and its files' buffers
constexpr std::uint64_t kPixelImage = 24;      // R, G, B, Z, objectId, primId
constexpr std::uint64_t kCacheTag = 24;        // per line of a unit that is a cache
constexpr std::uint64_t kTraceChange = 16 * 3;  // a buffered waveform change, in its three stages
constexpr std::uint64_t kTraceWriter = 8ull << 20;

std::uint64_t sat_mul(std::uint64_t a, std::uint64_t b) {
  return a != 0 && b > ~std::uint64_t{0} / a ? ~std::uint64_t{0} : a * b;
}
std::uint64_t sat_add(std::uint64_t a, std::uint64_t b) { return a + b < a ? ~std::uint64_t{0} : a + b; }

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

std::uint64_t bytes_per_vertex(const RunShape& r) { return r.double_precision ? 84 : 72; }

std::uint64_t bytes_per_triangle(const RunShape& r) {
  if (!r.timed) return r.bvh ? (r.double_precision ? 260 : 210) : 120;
  return r.bvh ? (r.double_precision ? 300 : 250) : 160;
}

std::uint64_t MemoryEstimate::total() const {
  std::uint64_t t = 0;
  for (const Part& p : parts) t = sat_add(t, p.bytes);
  return t;
}

MemoryEstimate memory_estimate(const RunShape& r, std::uint64_t pixels, std::uint64_t rays_per_pixel,
                               const NumberSource& image) {
  MemoryEstimate e;
  e.parts.push_back({"the process itself", "", "", kBase});
  if (pixels) {
    std::ostringstream what;
    if (r.timed) {
      const bool analytic = r.level == Level::analytic;
      const std::uint64_t per_ray = analytic ? kRayAnalytic + kRayAnalyticPerUnit * r.units
                                             : kRayTimed + kRayTimedPerUnit * r.units;
      what << "the rays and image of a frame (" << pixels << " pixels x " << rays_per_pixel
           << (rays_per_pixel == 1 ? " ray at " : " rays at ") << per_ray
           << " bytes with " << r.units << " units)";
      e.parts.push_back({what.str(), image.file, image.place, sat_add(sat_mul(sat_mul(pixels, rays_per_pixel), per_ray),
                                                     sat_mul(pixels, kPixelImage))});
    } else {
      what << "the image of a frame (" << pixels << " pixels at " << kPixelReference << " bytes)";
      e.parts.push_back({what.str(), image.file, image.place, sat_mul(pixels, kPixelReference)});
    }
  }
  if (r.trace_changes)
    e.parts.push_back({"the waveform writer's buffer (" + std::to_string(r.trace_changes) + " changes)", "--trace-buffer",
                       std::to_string(r.trace_changes), sat_add(sat_mul(r.trace_changes, kTraceChange), kTraceWriter)});
  if (r.timeline) e.parts.push_back({"the timeline writer", "", "", 1ull << 20});
  return e;
}

void add_geometry(MemoryEstimate& e, const RunShape& r, std::uint64_t vertices, std::uint64_t triangles,
                  const std::string& scene_file) {
  const std::uint64_t pv = bytes_per_vertex(r), pt = bytes_per_triangle(r);
  e.parts.push_back({"the scene's geometry (" + std::to_string(triangles) + " triangles at " + std::to_string(pt) +
                         " bytes, " + std::to_string(vertices) + " vertices at " + std::to_string(pv) + ")",
                     scene_file, "", sat_add(sat_mul(vertices, pv), sat_mul(triangles, pt))});
  if (r.timed && r.sram_bytes) {
    // A unit whose spheres do not fit its memory keeps a tag per line of it; its spheres'
    // triangles are at most all of them (48 bytes each in the object memory's format).
    const std::uint64_t lines = std::min(r.sram_bytes, sat_mul(triangles, r.double_precision ? 96 : 48)) / r.line_bytes;
    e.parts.push_back({"the object memories' cache tags (" + std::to_string(lines) + " lines x " +
                           std::to_string(r.units) + " units)",
                       "memory.sram_bytes", byte_count_text(r.sram_bytes),
                       sat_mul(sat_mul(lines, kCacheTag), r.units)});
  }
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
