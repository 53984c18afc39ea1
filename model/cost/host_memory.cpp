#include "cost/host_memory.h"

#include <algorithm>
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

}  // namespace

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

// The rays a pixel's tree holds, for the memory estimate: the primary ray and a shadow ray per
// light, and where a material reflects or transmits that again per bounce (one secondary ray
// per bounce: the kitchen at depth 5 traces 10.8 rays per pixel against this estimate's 42, 6 lights;
// the tree's worst case, 2^(depth + 1) - 1 nearest-hit rays, would refuse every run).
std::uint64_t rays_per_pixel(const Scene& scene, int depth_bound) {
  const int depth = depth_bound >= 0 ? depth_bound : scene.depth;
  bool secondary = false;
  for (const Material& m : scene.materials) secondary = secondary || m.reflects() || m.transmits();
  return (1 + scene.lights.size()) * (secondary ? 1 + static_cast<std::uint64_t>(depth) : 1);
}

}  // namespace oprt
