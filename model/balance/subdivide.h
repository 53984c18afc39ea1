// Sphere subdivision (the paper's Fig. 9): an object's primitives split into K spatially
// coherent clusters, each later bounded by its own sphere; all share the object's motion.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

enum class SplitRule {
  balanced_san,  // equal SA x N per cluster (the default; see subdivide.cpp)
  median,        // equal counts along the longest axis (for comparison)
};

// K non-empty clusters (fewer if the object has fewer than K triangles); every triangle
// in exactly one. Deterministic.
std::vector<std::vector<std::uint32_t>> subdivide(const Mesh& mesh, int k, SplitRule rule = SplitRule::balanced_san);
// The same for the listed triangles only (indices into mesh.triangles, ascending).
std::vector<std::vector<std::uint32_t>> subdivide(const Mesh& mesh, const std::vector<std::uint32_t>& prims, int k,
                                                  SplitRule rule = SplitRule::balanced_san);

SplitRule split_rule_named(const std::string& name);  // "balanced" | "median"

}  // namespace oprt
