#include "ref/reference.h"
#include "test_scenes.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
// The ray through pixel (x, y) of shadow_box, by hand: fov 90 and a square image give
// screen coordinates s = 2 (x + 0.5) / n - 1 directly in units of the distance 10.
struct PixelRay {
  double sx, sy;
};
PixelRay pixel(int x, int y, int n) { return {2 * (x + 0.5) / n - 1, 1 - 2 * (y + 0.5) / n}; }

template <typename T>
FrameResult render(const Scene& s, int subdivide = 1) {
  const auto g = build_geometry<T>(s, make_spheres(s, subdivide));
  return render_reference(s, g, 0, s.width, s.height);
}
}  // namespace

TEMPLATE_TEST_CASE("reference: pixels hit the objects at hand-computed distances", "[reference]", float, double) {
  const int n = 64;
  const Scene s = test::shadow_box(n);
  const FrameResult r = render<TestType>(s);
  for (int y : {5, 31, 50})
    for (int x : {3, 20, 31, 40}) {
      const auto p = pixel(x, y, n);
      const std::size_t i = static_cast<std::size_t>(y) * n + x;
      // Wall at z = 0: the ray (sx, sy, -1) from z = 10 travels 10 |(sx, sy, -1)|.
      INFO("pixel " << x << "," << y);
      CHECK(r.image.object[i] == 0);
      CHECK(r.image.z[i] == Approx(10 * std::sqrt(p.sx * p.sx + p.sy * p.sy + 1)).epsilon(1e-6));
      // primId: the wall's diagonal runs from (-10,-10) to (10,10); below it (y < x) lies
      // triangle 0.
      CHECK(r.image.prim[i] == (p.sy < p.sx ? 0u : 1u));
    }
  // The occluder seen from the camera: at z = 5 it covers x in [3.5, 4.5], i.e. screen
  // coordinates [0.7, 0.9]; pixel 57 has sx = 0.7969. Distance 5 |(sx, sy, -1)|.
  const int x = 57, y = 31;
  const auto p = pixel(x, y, n);
  const std::size_t i = static_cast<std::size_t>(y) * n + x;
  CHECK(r.image.object[i] == 1);
  CHECK(r.image.z[i] == Approx(5 * std::sqrt(p.sx * p.sx + p.sy * p.sy + 1)).epsilon(1e-6));
}

TEMPLATE_TEST_CASE("reference: pixels in the occluder's shadow get only ambient light", "[reference]", float, double) {
  const int n = 64;
  const Scene s = test::shadow_box(n);
  const FrameResult r = render<TestType>(s);
  const float ambient = static_cast<float>(0.1 * 0.8);
  // Shadow on the wall: x in [-3, -1] -> screen [-0.3, -0.1] -> pixels 23..28; y in [-1, 1]
  // -> rows 29..34. Pixel (25, 31) lies inside.
  for (int x : {23, 25, 28})
    for (int y : {29, 31, 34}) {
      const std::size_t i = static_cast<std::size_t>(y) * n + x;
      INFO("pixel " << x << "," << y);
      CHECK(r.image.object[i] == 0);
      CHECK(r.image.r[i] == ambient);
    }
  // The mirror image (x in [1, 3]) is lit: brighter than ambient.
  for (int x : {35, 38, 40}) {
    const std::size_t i = static_cast<std::size_t>(31) * n + x;
    CHECK(r.image.r[i] > ambient * 2);
  }
  // Just outside the shadow's edge (pixel 21: x = -3.28) is lit.
  CHECK(r.image.r[31 * n + 21] > ambient * 2);
}

TEMPLATE_TEST_CASE("reference: ray and work counts add up", "[reference]", float, double) {
  const int n = 32;
  const Scene s = test::shadow_box(n);
  const FrameResult r = render<TestType>(s);
  // Every pixel hits something (the wall fills the view), so one primary ray per pixel and
  // one shadow ray per pixel whose surface faces the light (all of them here).
  CHECK(r.work.rays[0] == n * n);
  CHECK(r.work.rays[1] == n * n);
  const WorkCounts p = r.work.total(RayKind::primary);
  // Two spheres, every primary ray tested against both.
  CHECK(p.sphere_tests == 2 * n * n);
  // Triangle tests: 2 per entered sphere.
  CHECK(p.tri_tests() == 2 * p.transforms);
  // Every pixel's nearest hit is accepted somewhere: at least one accepted test per ray.
  CHECK(p.tri_hits >= static_cast<std::uint64_t>(n * n));
}

TEMPLATE_TEST_CASE("reference: the image does not depend on how objects are split into spheres",
                   "[reference]", float, double) {
  Scene s = test::shadow_box(48);
  // A finer wall so that subdivision has something to split.
  Mesh fine;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const double x0 = -10 + 2.5 * i, y0 = -10 + 2.5 * j;
      const auto b = static_cast<std::uint32_t>(fine.vertices.size());
      fine.vertices.insert(fine.vertices.end(), {{x0, y0, 0}, {x0 + 2.5, y0, 0}, {x0 + 2.5, y0 + 2.5, 0}, {x0, y0 + 2.5, 0}});
      fine.triangles.push_back({b, b + 1, b + 2});
      fine.triangles.push_back({b, b + 2, b + 3});
    }
  s.objects[0].mesh = fine;
  const FrameResult one = render<TestType>(s, 1);
  for (int k : {2, 3, 8}) {
    const FrameResult split = render<TestType>(s, k);
    INFO("subdivide " << k);
    CHECK(split.image == one.image);
  }
}
