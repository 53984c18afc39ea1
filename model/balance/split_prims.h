// A triangle as the object splits see it (subdivide.cpp, extent_split.cpp): its centroid and
// its bounding box.
#pragma once

#include "geom/bvh.h"
#include "scene/scene.h"

#include <cstdint>
#include <vector>

namespace oprt {

struct SplitPrim {
  std::uint32_t id;
  Vec3d centroid;
  Box<double> box;
};

// The listed triangles of `mesh` (indices into mesh.triangles), in that order.
inline std::vector<SplitPrim> split_prims(const Mesh& mesh, const std::vector<std::uint32_t>& ids) {
  std::vector<SplitPrim> prims;
  prims.reserve(ids.size());
  for (std::uint32_t t : ids) {
    SplitPrim q{t, Vec3d(0), {}};
    for (std::uint32_t v : mesh.triangles[t]) {
      q.centroid += mesh.vertices[v] / 3.0;
      q.box.extend(mesh.vertices[v]);
    }
    prims.push_back(q);
  }
  return prims;
}

}  // namespace oprt
