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
struct SceneLimits {
  std::uint64_t triangles = std::uint64_t{1} << 25;  // per scene: 33,554,432
  int parts_nesting = 32;
};
extern SceneLimits scene_limits;

// How formats that need choices are read (today only BART .aff: its tessellation of spheres
// and cones, and the size above which a group is split into several objects). The command
// line sets them with --tessellation and --max-object-triangles (whose default depends on
// --split: testbench/options.h).
struct LoadOptions {
  AffOptions aff;
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
