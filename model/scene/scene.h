// The scene in memory, whatever file it came from: materials, point lights, a camera path,
// and rigid objects, each a triangle mesh in its own local coordinates with a motion.
#pragma once

#include "scene/motion.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

struct Material {
  std::string name;
  Vec3d diffuse{0.8};
  Vec3d specular{0};
  double shininess = 32;
};

struct PointLight {
  Vec3d position{0};
  Vec3d color{1};
  MotionPtr motion;  // an animated light (BART's la): at frame f it is at motion(f) position
  Vec3d at(double frame) const { return motion ? motion->at(frame).point(position) : position; }
};

// Pinhole camera: eye looking at target, up fixing the roll, fov_y_deg the full vertical
// angle. Pixel (x, y), y = 0 the top row, is sampled through its centre.
struct Camera {
  Vec3d eye{0, 0, 5};
  Vec3d target{0};
  Vec3d up{0, 1, 0};
  double fov_y_deg = 45;
};

class CameraPath {
 public:
  virtual ~CameraPath() = default;
  virtual Camera at(double frame) const = 0;
};
using CameraPathPtr = std::shared_ptr<const CameraPath>;

class FixedCamera final : public CameraPath {
 public:
  explicit FixedCamera(const Camera& c) : c_(c) {}
  Camera at(double) const override { return c_; }

 private:
  Camera c_;
};

struct CameraKey {
  double frame = 0;
  Camera camera;
};
// Eye, target and up linear between keys, fov linear; clamps outside the keys.
class KeyframeCamera final : public CameraPath {
 public:
  explicit KeyframeCamera(std::vector<CameraKey> keys) : keys_(std::move(keys)) {}
  Camera at(double frame) const override;

 private:
  std::vector<CameraKey> keys_;
};

using Tri = std::array<std::uint32_t, 3>;

struct Mesh {
  std::vector<Vec3d> vertices;
  std::vector<Tri> triangles;
  void append(const Mesh& other, const Affine<double>& placed = Affine<double>::identity());
};

// Non-rigid geometry (BART's per-vertex animated triangles, `tpa`): vertex positions in the
// object's local frame that change with the frame. The engine re-bounds such an object
// every frame and rewrites its triangles in object memory (the transfer is charged).
class VertexMotion {
 public:
  virtual ~VertexMotion() = default;
  // Every vertex of the object's mesh at `frame`: same count and order as Mesh::vertices.
  virtual void at(double frame, std::vector<Vec3d>& vertices) const = 0;
};

struct Object {
  std::string name;
  std::uint32_t material = 0;
  Mesh mesh;  // local coordinates (for a deforming object: its frame-0 shape)
  MotionPtr motion;
  std::shared_ptr<const VertexMotion> deform;  // null for a rigid object
};

struct Scene {
  std::string source;  // the file it was loaded from
  int width = 256, height = 256;
  Vec3d background{0};
  Vec3d ambient{0.1};
  std::vector<PointLight> lights;
  std::vector<Material> materials;  // at least one
  std::vector<Object> objects;
  CameraPathPtr camera;
  int frame_count = 1;  // frames 0 .. frame_count - 1
  std::vector<std::string> notes;  // what a loader simplified, said once
  // What the file gets wrong that the loader tolerates, as the format's reference reader
  // does, each "FILE: PLACE: what and how it is read" (load_scene prints them to stderr).
  std::vector<std::string> warnings;

  std::size_t triangle_count() const;
};

}  // namespace oprt
