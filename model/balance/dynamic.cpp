#include "balance/dynamic.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

namespace oprt {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Solid angle of a sphere seen from outside it: a cap, 2 pi (1 - cos a), sin a = r / d.
// (pi r^2 / d^2 is its small-sphere limit and falls short for near spheres.)
double cap_sr(double r2, double d2) { return 2 * kPi * (1 - std::sqrt(1 - r2 / d2)); }
}  // namespace

std::vector<double> view_weights(const std::vector<Sphere<double>>& spheres, const std::vector<std::size_t>& prims,
                                 const Camera& cam, int width, int height, const std::vector<PointLight>& lights,
                                 const ViewCostModel& m) {
  const double pixels = static_cast<double>(width) * height;
  const double tan_y = std::tan(cam.fov_y_deg * kPi / 360), tan_x = tan_y * width / height;
  // Solid angle of the view frustum (a rectangular pyramid).
  const double view_sr = 4 * std::asin(std::sin(std::atan(tan_x)) * std::sin(std::atan(tan_y)));
  const double half_diag = std::atan(std::sqrt(tan_x * tan_x + tan_y * tan_y));  // widest angle off axis
  const Vec3d forward = glm::normalize(cam.target - cam.eye);

  std::vector<double> primary(spheres.size(), 0);
  double covered = 0;  // pixels that hit something, roughly: for the shadow-ray estimate
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const Vec3d to = spheres[s].c - cam.eye;
    const double d = std::sqrt(dot3(to, to)), r = spheres[s].r;
    if (d <= r) {
      primary[s] = pixels;
    } else {
      const double angular_radius = std::asin(std::min(1.0, r / d));
      const double off_axis = std::acos(std::clamp(dot3(to, forward) / d, -1.0, 1.0));
      if (off_axis - angular_radius > half_diag) continue;  // outside the view cone
      primary[s] = std::min(pixels, pixels * cap_sr(r * r, d * d) / view_sr);
    }
    covered += primary[s];
  }
  // Pixels that hit something (and so may send shadow rays): the spheres' coverage, at
  // most the image (they overlap).
  covered = std::min(pixels, covered);
  std::vector<double> w(spheres.size());
  const double rays = pixels * (1 + static_cast<double>(lights.size()));
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    double shadow = 0;
    for (const PointLight& l : lights) {
      const Vec3d to = spheres[s].c - l.position;
      const double d2 = dot3(to, to), r = spheres[s].r;
      shadow += d2 <= r * r ? covered : covered * cap_sr(r * r, d2) / (4 * kPi);
    }
    const double entering = primary[s] + shadow;
    w[s] = rays * m.sphere_cycles + entering * (m.transform_cycles + static_cast<double>(prims[s]) * m.triangle_cycles);
  }
  return w;
}

std::uint64_t moved_bytes(const Assignment& next, const Assignment& prev, const std::vector<std::uint64_t>& bytes) {
  std::uint64_t moved = 0;
  for (std::size_t u = 0; u < next.units(); ++u) {
    const std::set<std::uint32_t> had(u < prev.units() ? prev.unit[u].begin() : next.unit[u].end(),
                                      u < prev.units() ? prev.unit[u].end() : next.unit[u].end());
    for (std::uint32_t s : next.unit[u])
      if (!had.count(s)) moved += bytes[s];
  }
  return moved;
}

Assignment keep_in_place(const Assignment& next, const Assignment& prev, const std::vector<std::uint64_t>& bytes) {
  const std::size_t n = next.units();
  if (prev.units() != n) return next;
  std::vector<std::uint32_t> old_unit(bytes.size(), 0xFFFFFFFFu);
  for (std::size_t u = 0; u < n; ++u)
    for (std::uint32_t s : prev.unit[u]) old_unit[s] = static_cast<std::uint32_t>(u);
  // Shared bytes of each (new set, old unit) pair, largest first; ties by index.
  std::vector<std::tuple<std::uint64_t, std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::uint64_t> shared(n, 0);
    for (std::uint32_t s : next.unit[i])
      if (old_unit[s] < n) shared[old_unit[s]] += bytes[s];
    for (std::size_t j = 0; j < n; ++j)
      if (shared[j]) pairs.emplace_back(shared[j], i, j);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    return std::make_pair(std::get<1>(a), std::get<2>(a)) < std::make_pair(std::get<1>(b), std::get<2>(b));
  });
  std::vector<std::size_t> slot(n, n);  // new set -> unit
  std::vector<char> taken(n, 0);
  for (const auto& [b, i, j] : pairs)
    if (slot[i] == n && !taken[j]) slot[i] = j, taken[j] = 1;
  std::size_t free_unit = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (slot[i] == n) {
      while (taken[free_unit]) ++free_unit;
      slot[i] = free_unit;
      taken[free_unit] = 1;
    }
  Assignment out;
  out.unit.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.unit[slot[i]] = next.unit[i];
  return out;
}

}  // namespace oprt
