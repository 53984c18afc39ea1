// The scene in memory, whatever file it came from: materials, point lights, a camera path,
// and rigid objects, each a triangle mesh in its own local coordinates with a motion.
#pragma once

#include "scene/motion.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

// Phong shading uses diffuse, specular and shininess. reflect, transmit and ior are the
// Whitted terms as the files publish them (AFF: the specular colour Ks, Whitted's weight of the
// reflected ray, the transmittance T and the index of refraction; the scene JSON's "reflect" /
// "transmit" / "ior"; glTF: a perfect metal, the transmission and ior extensions). Whitted's
// recursion (ref/shading.h) issues a reflection ray where reflect is non-zero and a refraction
// ray where transmit is.
struct Material {
  std::string name;
  Vec3d diffuse{0.8};
  Vec3d specular{0};
  double shininess = 32;
  Vec3d reflect{0};   // weight of the mirror-reflected ray, per channel, in [0, 1]
  Vec3d transmit{0};  // weight of the refracted ray, per channel, in [0, 1]
  double ior = 1;     // index of refraction of the material's inside (1: none)
  bool reflects() const { return reflect.x > 0 || reflect.y > 0 || reflect.z > 0; }
  bool transmits() const { return transmit.x > 0 || transmit.y > 0 || transmit.z > 0; }
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

// Vertex normals as the file publishes them, per triangle corner (as BART's indexed meshes and
// OBJ give them: a vertex on a crease has one normal per side): corner k of triangle t has the
// normal normals[normal_index[t][k]]. normal_index is empty when no triangle has normals, else
// parallel to triangles, with kNoNormal in every corner of a triangle without normals (shaded
// flat). Normals are unit length, in the same frame as the vertices. Shading interpolates them
// (ref/shading.h, SurfacePoint::shading) for the lights' terms and the reflected and refracted
// directions; the geometric normal still decides which lights face the surface.
constexpr std::uint32_t kNoNormal = 0xffffffffu;

struct Mesh {
  std::vector<Vec3d> vertices;
  std::vector<Tri> triangles;
  std::vector<Vec3d> normals;
  std::vector<Tri> normal_index;
  bool has_normals(std::size_t t) const { return !normal_index.empty() && normal_index[t][0] != kNoNormal; }
  std::size_t triangles_with_normals() const;
  // `other` placed by `placed`: its vertices as points, its normals by the inverse transpose
  // of placed's linear part, renormalised (placed must be invertible).
  void append(const Mesh& other, const Affine<double>& placed = Affine<double>::identity());
};

// A vertex normal as a file writes it, made unit length; a zero one stays zero (its triangles
// are then given no normals: the loaders shade them flat).
Vec3d unit_or_zero(const Vec3d& n);

// The normal n (unit or not) carried by `a`: the inverse transpose of a's linear part,
// renormalised; a zero vector if a is singular or n is zero.
Vec3d transform_normal(const Affine<double>& a, const Vec3d& n);

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
  // Whitted's recursion bound: reflection and refraction rays at most this many bounces from
  // the camera (0: primary and shadow rays only). The scene JSON's "depth", overridden by the
  // architecture's gpp.depth and by --depth. Five: light passing through one of the kitchen's
  // glasses refracts four times (two walls, in and out), and the fifth bounce shows what lies
  // behind it; the museum's mirrors (weight 0.3 to 0.6) pass on at most 0.6^5 = 8 % by then.
  static constexpr int kDefaultDepth = 5;
  int depth = kDefaultDepth;
  std::vector<std::string> notes;  // what a loader simplified, said once
  // What the file gets wrong that the loader tolerates, as the format's reference reader
  // does, each "FILE: PLACE: what and how it is read" (load_scene prints them to stderr).
  std::vector<std::string> warnings;

  std::size_t triangle_count() const;
};

}  // namespace oprt
