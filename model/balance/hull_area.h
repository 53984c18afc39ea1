// Surface area of the convex hull of a point set: the reference body of the Crofton
// argument behind the sa_n weights (policy.h).
#pragma once

#include "geom/vec.h"
#include "scene/scene.h"

#include <optional>
#include <vector>

namespace oprt {

// Area of the convex hull (Qhull), or nothing if the points span less than three
// dimensions (fewer than four points, or all coplanar): such a hull has no interior.
std::optional<double> convex_hull_area(const std::vector<Vec3d>& points);

// A_H of the sa_n weights (policy.h) and of the split by extent (spheres.cpp): the area of
// the convex hull of every vertex at frame 0; for a flat scene (no hull with an interior)
// the area of its minimal enclosing sphere.
double scene_hull_area(const Scene& scene);

}  // namespace oprt
