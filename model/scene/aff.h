// BART's Animated File Format (.aff): the scene description of "BART: A Benchmark for
// Animated Ray Tracing" (Lext, Assarsson, Moller, 2000), read into the in-memory Scene.
// How each construct maps (the full argument is beside the code in load_aff.cpp):
//
// - Time. `a start end frames` gives frame_count = frames; frame f is animation time
//   start + f (end - start) / (frames - 1), BART's own step. No `a`: one frame, time 0.
// - Objects. Every animated transform `x name { ... }` is a rigid group: its geometry, in
//   its own frame, becomes objects whose motion is the product of the enclosing transforms
//   evaluated per frame (static `xs` matrices and the `k name` keyframe curves). Geometry
//   under no `x` is static: it is placed in world coordinates. Within one such group the
//   triangles are split by material (an Object has one) and then, if a part has more than
//   `max_object_triangles`, recursively at the median of the triangle centroids along the
//   longest axis of their bounds (oprt's --split count; under --split extent the command
//   line passes 0 and balance/extent_split.h splits the objects' spheres by extent).
// - `tpa` triangles (per-vertex keyframes, linearly interpolated as BART defines them)
//   form one deforming object per group and material, with Object::deform set and the
//   mesh holding the frame-0 shape. They are not split.
// - Spheres and cones are tessellated (counts below); texture names, texture coordinates
//   and vertex normals are read, checked and dropped (flat Phong shading). Scene::notes
//   says which of these simplifications a scene needed.
#pragma once

#include "scene/scene.h"

#include <cstddef>
#include <string>

namespace oprt {

struct AffOptions {
  // A static (or rigid) group with more triangles is split into spatially coherent parts of
  // at most this many. 0 disables splitting. (The command line's default: this under
  // --split count, 0 under --split extent; testbench/options.h.)
  std::size_t max_object_triangles = 4096;
  // Sphere `s`: a UV sphere of 2 * segments * (rings - 1) triangles (224 by default).
  unsigned sphere_segments = 16;
  unsigned sphere_rings = 8;
  // Cone / cylinder `c`: the open side surface (AFF cones have no end caps), 2 * segments
  // triangles, or segments when one end has radius zero.
  unsigned cone_segments = 16;
};

// Every problem is an InputError naming the file (the included file where it lies) and
// "line N". Includes resolve relative to the including file; a cycle is an error.
Scene load_aff(const std::string& path, const AffOptions& options = {});

}  // namespace oprt
