// The untimed functional reference of the paper's algorithm: per pixel one primary ray,
// nearest hit over every bounding sphere (brute force inside each), Phong shading with one
// any-hit shadow ray per light. It is one intersection unit holding every sphere in scene
// order, so its work counts are the paper's per-object counts. Pixels are traced on every
// thread the pool allows (ref/parallel.h); the image and the counts do not depend on how many.
#pragma once

#include "ref/image.h"
#include "ref/shading.h"

#include <array>
#include <vector>

namespace oprt {

struct FrameWork {
  // [ray kind][sphere]
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;
  std::array<std::uint64_t, kRayKinds> rays{};
  // [depth][ray kind]: rays, up to the deepest a ray reached (a shadow ray counts at its
  // hit's depth); the timed model's stats.json ray_kinds.by_depth in the same shape.
  std::vector<std::array<std::uint64_t, kRayKinds>> by_depth;

  explicit FrameWork(std::size_t spheres = 0) {
    for (auto& v : per_sphere) v.assign(spheres, WorkCounts{});
  }
  WorkCounts total(RayKind k) const;
  WorkCounts total() const;
  FrameWork& operator+=(const FrameWork& o);
};

struct FrameResult {
  FrameImage image;
  FrameWork work;
};

template <typename T>
// depth: Whitted's recursion bound (-1: the scene's).
FrameResult render_reference(const Scene& scene, const SceneGeometry<T>& g, int frame, int width, int height,
                             int depth = -1);

extern template FrameResult render_reference(const Scene&, const SceneGeometry<float>&, int, int, int, int);
extern template FrameResult render_reference(const Scene&, const SceneGeometry<double>&, int, int, int, int);

}  // namespace oprt
