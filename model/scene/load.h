// Loading a scene file into memory. The format is chosen by extension: .json (oprt-scene/1),
// .aff (BART), .gltf / .glb (glTF 2.0). Every failure is an InputError.
#pragma once

#include "scene/aff.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>

namespace oprt {

// What an oprt-scene/1 file may ask for, checked before memory is allocated: a few bytes of
// JSON can ask generators for billions of triangles, or nest "parts" deep enough to
// overflow the stack. Fuzz targets lower the triangle limit to stay within their memory.
//
// The memory a run may use is checked here too, when a renderer has set it (testbench/
// memory_estimate.h): `memory_limit` bytes (0: none; `memory_limit_source` says where the
// limit comes from), of which `memory_reserved` are the rest of the run's needs; each vertex
// and triangle the scene makes costs the run `bytes_per_vertex` and `bytes_per_triangle`, in
// every form it keeps them (the mesh, the engine's copy, the BVH, working lists).
struct SceneLimits {
  std::uint64_t triangles = std::uint64_t{1} << 25;  // per scene: 33,554,432
  int parts_nesting = 32;
  std::uint64_t memory_limit = 0, memory_reserved = 0, bytes_per_vertex = 0, bytes_per_triangle = 0;
  std::string memory_limit_source;
};
extern SceneLimits scene_limits;

// A scene's meshes counted against scene_limits as they are made: a loader asks before it
// makes a mesh whose size it knows (a generator, a tessellated sphere) and counts every mesh
// it has made (one read from a file is bounded by the file's size).
class MeshBudget {
 public:
  MeshBudget() : max_triangles_(scene_limits.triangles) {}
  explicit MeshBudget(std::uint64_t max_triangles) : max_triangles_(max_triangles) {}
  // Throws InputError(file, place, "WHAT would make ...") if the scene cannot have `vertices`
  // and `triangles` more: past the triangle limit, or past the run's memory.
  void check(const std::string& file, const std::string& place, const std::string& what, std::uint64_t vertices,
             std::uint64_t triangles) const;
  // check(), then counts them.
  void charge(const std::string& file, const std::string& place, const std::string& what, std::uint64_t vertices,
              std::uint64_t triangles);
  std::uint64_t triangles() const { return triangles_; }
  std::uint64_t triangles_left() const { return max_triangles_ - triangles_; }

 private:
  std::uint64_t max_triangles_, vertices_ = 0, triangles_ = 0;
};

// How formats that need choices are read (today only BART .aff: its tessellation of spheres
// and cones, and the size above which a group is split into several objects). The command
// line sets them with --tessellation and --max-object-triangles (whose default depends on
// --split: testbench/options.h).
struct LoadOptions {
  AffOptions aff;
  bool print_warnings = true;  // Scene::warnings to stderr, each as "oprt: warning: ..."
};

Scene load_scene(const std::string& path, const LoadOptions& options = {});
Scene load_oprt_json(const std::string& path);
// glTF 2.0 rigid node animation; load_gltf.cpp says what maps to what.
Scene load_gltf(const std::string& path);
Mesh load_obj(const std::string& path);

// Checks shared by every loader: at least one object, every object with triangles, indices
// in range, finite vertices, materials in range, motions invertible at frame 0.
// Motions are checked at frame 0 only: a scene may have a million frames of a thousand
// objects, and checking them all would take minutes before anything is rendered.
void validate_scene(const Scene& scene);
// Every object's motion invertible at frames first..last: the renderers check the frames
// they were asked for before rendering the first.
void check_motions(const Scene& scene, int first, int last);

}  // namespace oprt
