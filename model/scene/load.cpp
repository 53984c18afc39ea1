#include "scene/load.h"

#include "scene/aff.h"
#include "base/error.h"
#include "base/numbers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace oprt {

SceneLimits scene_limits;

void MeshBudget::check(const std::string& file, const std::string& place, const std::string& what,
                       std::uint64_t vertices, std::uint64_t triangles) const {
  if (triangles > triangles_left())
    throw InputError(file, place,
                     what + " would make " + std::to_string(triangles) + " triangles, more than the " +
                         std::to_string(triangles_left()) + " the scene may still have (a scene may have " +
                         std::to_string(max_triangles_) + ")");
  const SceneLimits& l = scene_limits;
  if (l.memory_limit == 0) return;
  // Each factor is below 2^40 (counts below 2^25 plus a generator's below 2^50 are refused
  // above): no product here wraps.
  const std::uint64_t v = std::min<std::uint64_t>(vertices_ + vertices, std::uint64_t{1} << 40);
  const std::uint64_t geometry = v * l.bytes_per_vertex + (triangles_ + triangles) * l.bytes_per_triangle;
  if (l.memory_reserved + geometry > l.memory_limit)
    throw InputError(file, place,
                     what + " would make " + std::to_string(triangles) + " triangles and " + std::to_string(vertices) +
                         " vertices: the run would need about " + byte_count_text(l.memory_reserved + geometry) +
                         " (the scene's geometry " + byte_count_text(geometry) + ", at " +
                         std::to_string(l.bytes_per_triangle) + " bytes a triangle and " +
                         std::to_string(l.bytes_per_vertex) + " a vertex, with " + std::to_string(triangles_) +
                         " triangles before it; the rest of the run " + byte_count_text(l.memory_reserved) +
                         "), more than the " + byte_count_text(l.memory_limit) + " it may use (" +
                         l.memory_limit_source + ")");
}

void MeshBudget::charge(const std::string& file, const std::string& place, const std::string& what,
                        std::uint64_t vertices, std::uint64_t triangles) {
  check(file, place, what, vertices, triangles);
  vertices_ += vertices;
  triangles_ += triangles;
}

namespace {
constexpr double kMaxCoordinate = 1e18;
}

namespace {
Scene load_by_extension(const std::string& path, const LoadOptions& options) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  require_regular_file(path);
  if (ext == ".json") return load_oprt_json(path);
  if (ext == ".aff") return load_aff(path, options.aff);
  if (ext == ".gltf" || ext == ".glb") {
    // Its meshes are read from buffers, whose size bounds them; counted once loaded.
    Scene s = load_gltf(path);
    std::uint64_t vertices = 0;
    for (const Object& o : s.objects) vertices += o.mesh.vertices.size();
    MeshBudget().charge(path, "", "the scene", vertices, s.triangle_count());
    return s;
  }
  throw InputError(path, "", "unknown scene format \"" + ext + "\" (expected .json, .aff, .gltf or .glb)");
}
}  // namespace

Scene load_scene(const std::string& path, const LoadOptions& options) {
  Scene s = load_by_extension(path, options);
  if (options.print_warnings)
    for (const std::string& w : s.warnings) std::fprintf(stderr, "oprt: warning: %s\n", w.c_str());
  return s;
}

void validate_scene(const Scene& s) {
  const std::string& f = s.source;
  if (s.objects.empty()) throw InputError(f, "objects", "scene has no objects");
  if (!s.camera) throw InputError(f, "camera", "scene has no camera");
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const Object& o = s.objects[i];
    const std::string where = "object " + std::to_string(i) + " (\"" + o.name + "\")";
    if (o.mesh.triangles.empty()) throw InputError(f, where, "object has no triangles");
    if (o.material >= s.materials.size()) throw InputError(f, where, "material index out of range");
    for (std::size_t v = 0; v < o.mesh.vertices.size(); ++v) {
      const Vec3d& p = o.mesh.vertices[v];
      if (!all_finite(p)) throw InputError(f, where + " vertex " + std::to_string(v), "coordinate is not finite");
      // The float kernels square distances: beyond 1e18 a square overflows float's 3.4e38
      // and the ray tests return infinities rather than hits.
      if (std::fabs(p.x) > kMaxCoordinate || std::fabs(p.y) > kMaxCoordinate || std::fabs(p.z) > kMaxCoordinate)
        throw InputError(f, where + " vertex " + std::to_string(v),
                         "coordinate beyond +-1e18, which float precision cannot square");
    }
    for (std::size_t t = 0; t < o.mesh.triangles.size(); ++t)
      for (std::uint32_t k : o.mesh.triangles[t])
        if (k >= o.mesh.vertices.size())
          throw InputError(f, where + " triangle " + std::to_string(t),
                           "vertex index " + std::to_string(k) + " out of range");
    if (!o.mesh.normal_index.empty() && o.mesh.normal_index.size() != o.mesh.triangles.size())
      throw InputError(f, where, "vertex normal indices are not one per triangle");
    for (std::size_t t = 0; t < o.mesh.normal_index.size(); ++t)
      for (std::uint32_t k : o.mesh.normal_index[t])
        if (k != kNoNormal && k >= o.mesh.normals.size())
          throw InputError(f, where + " triangle " + std::to_string(t),
                           "normal index " + std::to_string(k) + " out of range");
    for (std::size_t n = 0; n < o.mesh.normals.size(); ++n)
      if (!all_finite(o.mesh.normals[n]))
        throw InputError(f, where + " normal " + std::to_string(n), "normal is not finite");
    if (!o.motion) throw InputError(f, where, "object has no motion");
  }
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    const Material& m = s.materials[i];
    const std::string where = "material " + std::to_string(i) + " (\"" + m.name + "\")";
    if (!all_finite(m.reflect) || !all_finite(m.transmit) || !std::isfinite(m.ior))
      throw InputError(f, where, "reflection, transmission or index of refraction is not finite");
  }
  check_motions(s, 0, 0);
  for (std::size_t i = 0; i < s.lights.size(); ++i)
    if (!all_finite(s.lights[i].position) || !all_finite(s.lights[i].color))
      throw InputError(f, "light " + std::to_string(i), "position or colour is not finite");
}

void check_motions(const Scene& s, int first, int last) {
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const Object& o = s.objects[i];
    for (int fr = first; fr <= last; ++fr) {
      const std::string why = why_not_invertible(o.motion->at(fr));
      if (!why.empty())
        throw InputError(s.source, "object " + std::to_string(i) + " (\"" + o.name + "\") at frame " + std::to_string(fr),
                         why);
      if (!o.motion->animated()) break;
    }
  }
}

}  // namespace oprt
