// Bounding spheres of point sets (a sphere's triangles are bounded by their vertices).
#pragma once

#include "geom/sphere.h"

#include <vector>

namespace oprt {

// The minimal enclosing sphere (Welzl 1991, in the iterative move-to-front form of
// Gaertner 1999), in double. Randomised with a fixed seed, so the result is reproducible.
// The returned radius is re-measured as the largest distance from the returned centre to
// any point, so the sphere encloses every point even where the support-set arithmetic
// rounded badly (nearly coplanar support points); tightness is what rounding can cost,
// never enclosure.
Sphere<double> minimal_sphere(const std::vector<Vec3d>& points);

// Ritter's (1990) two-pass approximation, for comparison: typically 5-20 % larger.
Sphere<double> ritter_sphere(const std::vector<Vec3d>& points);

// Largest distance from c to the points.
double enclosing_radius(const std::vector<Vec3d>& points, const Vec3d& c);

}  // namespace oprt
