#include "scene/load.h"

#include "scene/aff.h"
#include "scene/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace oprt {

SceneLimits scene_limits;

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
  if (ext == ".gltf" || ext == ".glb") return load_gltf(path);
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
    if (!o.motion) throw InputError(f, where, "object has no motion");
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
