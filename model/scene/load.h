// Loading a scene file into memory. The format is chosen by extension: .json (oprt-scene/1),
// .aff (BART), .gltf / .glb (glTF 2.0). Every failure is an InputError.
#pragma once

#include "scene/aff.h"
#include "scene/scene.h"

#include <string>

namespace oprt {

// How formats that need choices are read (today only BART .aff: its tessellation of spheres
// and cones, and the size above which a group is split into several objects). The command
// line sets them with --tessellation and --max-object-triangles.
struct LoadOptions {
  AffOptions aff;
};

Scene load_scene(const std::string& path, const LoadOptions& options = {});
Scene load_oprt_json(const std::string& path);
// glTF 2.0 rigid node animation; load_gltf.cpp says what maps to what.
Scene load_gltf(const std::string& path);
Mesh load_obj(const std::string& path);

// Checks shared by every loader: at least one object, every object with triangles, indices
// in range, finite vertices, materials in range, motions invertible at every frame.
void validate_scene(const Scene& scene);

}  // namespace oprt
