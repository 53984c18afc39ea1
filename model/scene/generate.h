// Procedural meshes, in local coordinates: what the shipped scenes are built from, so the
// repository holds recipes rather than large mesh files. Every generator is deterministic
// (seeded), and its triangle count is a closed formula of its parameters (see count_*).
#pragma once

#include "base/json_in.h"
#include "scene/load.h"
#include "scene/scene.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace oprt {

// Small random triangles filling a ball (BART museum's "flying triangles"): each triangle's
// centre uniform in the ball of `radius`, its vertices at `size` (edge scale) around it.
Mesh triangle_cloud(std::uint32_t count, double radius, double size, std::uint64_t seed);
// Axis-aligned box centred at the origin, each face split into divisions^2 quads.
Mesh box(const Vec3d& size, std::uint32_t divisions);
// UV sphere: segments around, rings from pole to pole: 2 * segments * (rings - 1) triangles.
Mesh uv_sphere(double radius, std::uint32_t segments, std::uint32_t rings);
// Cylinder along +y from 0 to height: 2 * segments side triangles, plus segments per cap.
Mesh cylinder(double radius, double height, std::uint32_t segments, bool caps);
// Torus in the xz plane: 2 * segments * sides triangles.
Mesh torus(double major, double minor, std::uint32_t segments, std::uint32_t sides);
// Grid in the xz plane facing +y, centred: 2 * nx * nz triangles.
Mesh plane(double width, double depth, std::uint32_t nx, std::uint32_t nz);
// Surface of revolution about +y (vases, lamp shades, bowls): profile points (r, y), r > 0,
// swept through `segments` steps: 2 * segments * (profile.size() - 1) triangles, plus
// `segments` per cap (a fan closing the first / last profile ring).
Mesh lathe(const std::vector<std::pair<double, double>>& profile, std::uint32_t segments, bool cap_first,
           bool cap_last);

// {"generate": {"kind": ..., ...}} from a scene file. The mesh's size is computed from the
// parameters first and charged to `budget` (scene/load.h), which refuses it before anything
// is allocated: a few bytes of JSON can ask for billions of triangles.
Mesh generate_from_json(const JsonIn& spec, MeshBudget& budget);
// The same against a triangle limit alone.
Mesh generate_from_json(const JsonIn& spec, std::uint64_t max_triangles = std::uint64_t{1} << 25);

}  // namespace oprt
