#include "balance/hull_area.h"

#include "geom/bounding_sphere.h"

#include <algorithm>

#include <cstdio>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace oprt {

std::optional<double> convex_hull_area(const std::vector<Vec3d>& points) {
  if (points.size() < 4) return std::nullopt;
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (const Vec3d& p : points) coords.insert(coords.end(), {p.x, p.y, p.z});
  // Qhull reports a degenerate input (a flat scene) on its error stream: that is an
  // expected answer here, not a message for the user.
  std::FILE* quiet = std::fopen("/dev/null", "w");
  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, quiet);
  char options[] = "qhull FA";  // FA: compute the facets' total area
  const int status = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False, options, nullptr, quiet);
  std::optional<double> area;
  if (status == 0) {
    if (!qh->hasAreaVolume) qh_getarea(qh, qh->facet_list);
    if (qh->totarea > 0) area = qh->totarea;
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (quiet) std::fclose(quiet);
  return area;
}

double scene_hull_area(const Scene& scene) {
  std::vector<Vec3d> points;
  for (const Object& o : scene.objects) {
    const Affine<double> m = o.motion->at(0);
    for (const Vec3d& v : o.mesh.vertices) points.push_back(m.point(v));
  }
  if (const auto area = convex_hull_area(points)) return *area;
  const double r = points.empty() ? 1 : std::max(minimal_sphere(points).r, 1e-30);
  return 4 * 3.14159265358979323846 * r * r;
}

}  // namespace oprt
