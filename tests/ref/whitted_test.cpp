// Whitted's recursion (ref/shading.h, ref/frame_trace.h) on scenes built so that every
// outcome can be worked out by hand: a mirror in front of a coloured plane, Snell's law at a
// glass slab, the depth bound between two facing mirrors, and interpolated vertex normals.
#include "ref/frame_trace.h"
#include "ref/reference.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <numeric>

using namespace oprt;

namespace {

Mesh quad(double cx, double cy, double cz, double half) {
  Mesh m;
  m.vertices = {{cx - half, cy - half, cz}, {cx + half, cy - half, cz}, {cx + half, cy + half, cz},
                {cx - half, cy + half, cz}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

Object object(const std::string& name, std::uint32_t material, Mesh mesh) {
  return Object{name, material, std::move(mesh), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr};
}

// Camera at (0, 0, 10) looking down -z, square image of n pixels: with fov 90 (tan = 1) the
// ray through pixel (x, y) is (sx, sy, -1), sx = 2 (x + 0.5) / n - 1, sy = 1 - 2 (y + 0.5) / n.
Scene camera_scene(int n, double fov_y_deg = 90) {
  Scene s;
  s.source = "whitted_test (built in code)";
  s.width = s.height = n;
  Camera c;
  c.eye = {0, 0, 10};
  c.target = {0, 0, 0};
  c.up = {0, 1, 0};
  c.fov_y_deg = fov_y_deg;
  s.camera = std::make_shared<FixedCamera>(c);
  s.background = Vec3d(0.05);
  return s;
}

double screen(int i, int n) { return 2 * (i + 0.5) / n - 1; }

template <typename T>
FrameResult render(const Scene& s, int depth) {
  const auto g = build_geometry<T>(s, make_spheres(s, 1));
  return render_reference(s, g, 0, s.width, s.height, depth);
}

// Counts a frame's rays per kind and per depth, as the recorder of trace_pixel sees them.
struct DepthCounter : RecorderBase {
  std::array<std::array<std::uint64_t, kRayKinds>, kMaxDepth + 1> rays{};
  template <typename Ray>
  void begin_ray(const Ray&, RayKind k, std::size_t, int depth) {
    ++rays.at(static_cast<std::size_t>(depth))[static_cast<int>(k)];
  }
};

template <typename T>
DepthCounter count_rays(const Scene& s, int depth) {
  const auto g = build_geometry<T>(s, make_spheres(s, 1));
  const FrameSetup<T> f = setup_frame(s, g, 0);
  const CameraRays camera(f.camera, s.width, s.height);
  const Shader<T> shader(s, f, depth);
  std::vector<std::uint32_t> all(g.sphere_count());
  std::iota(all.begin(), all.end(), 0u);
  std::vector<IuRegisters<T>> one_unit(1);
  one_unit[0].load(f, g, all);
  const FrameTraceInputs<T> in{g, one_unit, camera, shader};
  FrameImage image(s.width, s.height);
  PixelScratch<T> scratch;
  DepthCounter rec;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) trace_pixel(in, x, y, image, rec, scratch);
  return rec;
}

// A mirror (reflect 1, diffuse 0, a specular highlight 0.5 with shininess 1) filling the
// view in the plane z = 0, and behind the camera, facing it, a diffuse plane at z = 20
// (diffuse (0.2, 0.6, 0.4)). Ambient 0.1, one light at (3, 2, 15) of colour (1, 0.9, 0.8).
Scene mirror_and_plane(int n) {
  Scene s = camera_scene(n);
  s.ambient = Vec3d(0.1);
  s.lights.push_back({{3, 2, 15}, {1, 0.9, 0.8}, nullptr});
  Material mirror{"mirror", Vec3d(0), Vec3d(0.5), 1};
  mirror.reflect = Vec3d(1);
  s.materials.push_back(mirror);
  s.materials.push_back({"paint", {0.2, 0.6, 0.4}, Vec3d(0), 1});
  s.objects.push_back(object("mirror", 0, quad(0, 0, 0, 12)));
  s.objects.push_back(object("plane", 1, quad(0, 0, 20, 40)));
  return s;
}

}  // namespace

TEMPLATE_TEST_CASE("whitted: a mirror shows the plane it faces, shaded, times its weight; at depth 0 only its own terms",
                   "[ref][whitted]", float, double) {
  const int n = 9;
  const Scene s = mirror_and_plane(n);
  const Vec3d light{3, 2, 15}, lc{1, 0.9, 0.8}, kd_plane{0.2, 0.6, 0.4};
  const FrameResult deep = render<TestType>(s, 5);
  const FrameResult flat = render<TestType>(s, 0);
  for (int y : {0, 2, 4, 8})
    for (int x : {0, 3, 4, 7}) {
      INFO("pixel " << x << "," << y);
      const std::size_t i = static_cast<std::size_t>(y) * n + x;
      const double sx = screen(x, n), sy = -screen(y, n);
      // The primary ray hits the mirror at P = (10 sx, 10 sy, 0); its own terms: ambient
      // x diffuse 0, the light's diffuse 0 and its highlight 0.5 (R.V)^1.
      const Vec3d d = glm::normalize(Vec3d(sx, sy, -1));
      const Vec3d p{10 * sx, 10 * sy, 0}, n_mirror{0, 0, 1};
      const Vec3d l = glm::normalize(light - p);
      const Vec3d r = n_mirror * (2 * dot3(n_mirror, l)) - l;
      const Vec3d own = 0.5 * std::max(0.0, dot3(r, -d)) * lc;
      // The reflected ray (sx, sy, 1) reaches the plane z = 20 at Q = (30 sx, 30 sy, 20), seen
      // from below (normal (0, 0, -1)): ambient 0.1 kd plus kd (N.L) times the light.
      const Vec3d q{30 * sx, 30 * sy, 20}, n_plane{0, 0, -1};
      const Vec3d plane = 0.1 * kd_plane + kd_plane * std::max(0.0, dot3(n_plane, glm::normalize(light - q))) * lc;
      const Vec3d want = own + 1.0 * plane;
      CHECK(deep.image.object[i] == 0);
      CHECK(deep.image.r[i] == Approx(want.x).epsilon(2e-5));
      CHECK(deep.image.g[i] == Approx(want.y).epsilon(2e-5));
      CHECK(deep.image.b[i] == Approx(want.z).epsilon(2e-5));
      CHECK(flat.image.object[i] == 0);
      CHECK(flat.image.r[i] == Approx(own.x).epsilon(2e-5));
      CHECK(flat.image.g[i] == Approx(own.y).epsilon(2e-5));
      CHECK(flat.image.b[i] == Approx(own.z).epsilon(2e-5));
      CHECK(flat.image.z[i] == deep.image.z[i]);  // the primary hit is the same
    }
  // Every pixel: a primary ray, a shadow ray from the mirror, and at depth >= 1 a reflection
  // ray whose hit on the plane sends one more shadow ray; no refraction.
  const std::uint64_t px = n * n;
  CHECK(deep.work.rays == std::array<std::uint64_t, kRayKinds>{px, 2 * px, px, 0});
  CHECK(flat.work.rays == std::array<std::uint64_t, kRayKinds>{px, px, 0, 0});
}

namespace {
// A glass slab (transmit 1, ior 1.5, reflect 0) between z = -1 and z = 0, 20 wide; no
// lights, so a hit spawns only its reflection or refraction ray. Triangles 0 and 1 are the
// top face, 2 and 3 the bottom one.
Scene glass_slab() {
  Scene s = camera_scene(4);
  Material glass{"glass", Vec3d(0), Vec3d(0), 1};
  glass.transmit = Vec3d(1);
  glass.ior = 1.5;
  s.materials.push_back(glass);
  Mesh slab = quad(0, 0, 0, 10);
  slab.append(quad(0, 0, -1, 10));
  s.objects.push_back(object("slab", 0, slab));
  return s;
}

// What the shader spawns for a ray of direction d (unit) hitting triangle `prim` of the slab
// at the point of barycentrics (0.25, 0.35), i.e. (2, -3) in the face's plane.
template <typename T>
std::vector<SpawnedRay<T>> shade_slab(const Vec3d& d, std::uint32_t prim, bool inside) {
  const Scene s = glass_slab();
  const auto g = build_geometry<T>(s, make_spheres(s, 1));
  const FrameSetup<T> f = setup_frame(s, g, 0);
  const Shader<T> shader(s, f, 5);
  const double z = prim < 2 ? 0 : -1;
  const Vec3d p{2, -3, z};
  HitRecord<T> hit;
  hit.object = 0;
  hit.prim = prim;
  hit.sphere = 0;
  hit.u = static_cast<T>(0.25);
  hit.v = static_cast<T>(0.35);
  hit.t = 1;
  const Ray<T> ray{Vec3<T>(p - d), Vec3<T>(d), kInf<T>};
  std::vector<SpawnedRay<T>> out;
  const Vec3d colour = shader.shade(ray, hit, 0, inside, out);
  CHECK(colour == Vec3d(0));  // ambient 0
  return out;
}

void check_direction(const Vec3d& got, const Vec3d& want, double tol) {
  INFO("got " << got.x << " " << got.y << " " << got.z << ", want " << want.x << " " << want.y << " " << want.z);
  CHECK(std::abs(got.x - want.x) < tol);
  CHECK(std::abs(got.y - want.y) < tol);
  CHECK(std::abs(got.z - want.z) < tol);
}

constexpr double kPi = 3.14159265358979323846;
}  // namespace

TEMPLATE_TEST_CASE("whitted: Snell's law into and out of a glass slab, and total internal reflection past the critical angle",
                   "[ref][whitted][snell]", float, double) {
  const double tol = std::is_same<TestType, float>::value ? 1e-6 : 1e-12;
  const double i30 = 30 * kPi / 180;
  const Vec3d in{std::sin(i30), 0, -std::cos(i30)};
  // Entering at 30 degrees: sin t = sin 30 / 1.5 = 1/3, so T = (1/3, 0, -sqrt(8)/3).
  const auto enter = shade_slab<TestType>(in, 0, false);
  REQUIRE(enter.size() == 1);
  CHECK(enter[0].kind == RayKind::refraction);
  CHECK(enter[0].inside);
  CHECK(enter[0].weight == Vec3d(1));
  const Vec3d t = glm::normalize(Vec3d(enter[0].ray.d));
  check_direction(t, {1.0 / 3, 0, -std::sqrt(8.0) / 3}, tol);
  // It starts below the top face (inside the glass), within rounding of the hit point.
  CHECK(enter[0].ray.o.z < 0);
  CHECK(glm::length(Vec3d(enter[0].ray.o) - Vec3d(2, -3, 0)) < 1e-4);
  CHECK(enter[0].ray.tmax == kInf<TestType>);

  // Leaving through the bottom face: sin = 1.5 x 1/3 = 1/2, the incoming direction again.
  const auto leave = shade_slab<TestType>(t, 2, true);
  REQUIRE(leave.size() == 1);
  CHECK(leave[0].kind == RayKind::refraction);
  CHECK_FALSE(leave[0].inside);
  const Vec3d out = glm::normalize(Vec3d(leave[0].ray.d));
  check_direction(out, in, 4 * tol);
  CHECK(dot3(out, in) == Approx(1).epsilon(tol));
  CHECK(leave[0].ray.o.z < -1);

  // From inside, the critical angle is asin(1 / 1.5) = 41.81 degrees: at 41 the ray leaves,
  // bent to sin = 1.5 sin 41 = 0.9841; at 42 it is reflected, with the transmitted weight,
  // back into the glass: (sin 42, 0, cos 42), and no refraction ray is issued.
  const double i41 = 41 * kPi / 180, i42 = 42 * kPi / 180;
  const auto just = shade_slab<TestType>({std::sin(i41), 0, -std::cos(i41)}, 2, true);
  REQUIRE(just.size() == 1);
  CHECK(just[0].kind == RayKind::refraction);
  const double s41 = 1.5 * std::sin(i41);
  check_direction(glm::normalize(Vec3d(just[0].ray.d)), {s41, 0, -std::sqrt(1 - s41 * s41)}, 10 * tol);
  const auto tir = shade_slab<TestType>({std::sin(i42), 0, -std::cos(i42)}, 2, true);
  REQUIRE(tir.size() == 1);
  CHECK(tir[0].kind == RayKind::reflection);
  CHECK(tir[0].inside);            // it stays in the glass
  CHECK(tir[0].weight == Vec3d(1));  // reflect 0 + transmit 1
  check_direction(glm::normalize(Vec3d(tir[0].ray.d)), {std::sin(i42), 0, std::cos(i42)}, tol);
  CHECK(tir[0].ray.o.z > -1);
}

namespace {
// Two facing mirrors, z = 0 and z = 20, 2000 wide, the camera between them looking at the
// first with a narrow view (10 degrees), one light at (1, 1, 15): every ray bounces between
// them and never leaves within 16 bounces (drift at most 10 tan 5 + 20 x 16 tan 5 < 30).
Scene facing_mirrors(int n) {
  Scene s = camera_scene(n, 10);
  s.ambient = Vec3d(0.1);
  s.lights.push_back({{1, 1, 15}, Vec3d(1), nullptr});
  Material mirror{"mirror", Vec3d(0.1), Vec3d(0), 1};
  mirror.reflect = Vec3d(0.9);
  s.materials.push_back(mirror);
  s.objects.push_back(object("a", 0, quad(0, 0, 0, 1000)));
  s.objects.push_back(object("b", 0, quad(0, 0, 20, 1000)));
  return s;
}
}  // namespace

TEMPLATE_TEST_CASE("whitted: between two facing mirrors, depth N gives exactly N reflection rays per pixel, one per depth",
                   "[ref][whitted][depth]", float, double) {
  const int n = 4;
  const std::uint64_t px = n * n;
  Scene s = facing_mirrors(n);
  for (int depth : {0, 1, 2, 5, kMaxDepth}) {
    INFO("depth " << depth);
    // Per pixel: the primary ray (depth 0) and a reflection ray at each depth 1..N; each of
    // their hits faces the light and sends one shadow ray, counted at its parent's depth.
    const DepthCounter c = count_rays<TestType>(s, depth);
    for (int d = 0; d <= kMaxDepth; ++d) {
      INFO("at depth " << d);
      const std::uint64_t here = d <= depth ? px : 0;
      CHECK(c.rays[d][static_cast<int>(RayKind::primary)] == (d == 0 ? px : 0));
      CHECK(c.rays[d][static_cast<int>(RayKind::shadow)] == here);
      CHECK(c.rays[d][static_cast<int>(RayKind::reflection)] == (d >= 1 ? here : 0));
      CHECK(c.rays[d][static_cast<int>(RayKind::refraction)] == 0);
    }
    const std::uint64_t nd = static_cast<std::uint64_t>(depth);
    CHECK(render<TestType>(s, depth).work.rays == std::array<std::uint64_t, kRayKinds>{px, (nd + 1) * px, nd * px, 0});
  }
  // Depth -1 takes the scene's bound.
  s.depth = 3;
  CHECK(render<TestType>(s, -1).work.rays == std::array<std::uint64_t, kRayKinds>{px, 4 * px, 3 * px, 0});
}

namespace {
// A triangle in the plane z = 0, a = (-10, -10), b = (10, -10), c = (-10, 10), diffuse
// (0.5, 0.7, 0.9), no ambient, no highlight, one white light at (2, 3, 8); with `normals`,
// the published vertex normals (0, 0, 1) at a, (1, 0, 2) / sqrt 5 at b, (0, 1, 2) / sqrt 5 at c.
Scene normal_triangle(int n, int normals) {
  Scene s = camera_scene(n);
  s.ambient = Vec3d(0);
  s.lights.push_back({{2, 3, 8}, Vec3d(1), nullptr});
  s.materials.push_back({"matte", {0.5, 0.7, 0.9}, Vec3d(0), 1});
  Mesh m;
  m.vertices = {{-10, -10, 0}, {10, -10, 0}, {-10, 10, 0}};
  m.triangles = {{0, 1, 2}};
  if (normals == 1) m.normals = {{0, 0, 1}, glm::normalize(Vec3d(1, 0, 2)), glm::normalize(Vec3d(0, 1, 2))};
  if (normals == 2) m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};  // the face's own normal
  if (normals) m.normal_index = {{0, 1, 2}};
  s.objects.push_back(object("tri", 0, m));
  return s;
}
}  // namespace

TEMPLATE_TEST_CASE("whitted: published vertex normals are interpolated for the diffuse term; a flat triangle is unchanged",
                   "[ref][whitted][normals]", float, double) {
  const int n = 16;
  const Vec3d light{2, 3, 8}, kd{0.5, 0.7, 0.9};
  const FrameResult smooth = render<TestType>(normal_triangle(n, 1), 5);
  const FrameResult flat = render<TestType>(normal_triangle(n, 0), 5);
  const FrameResult face = render<TestType>(normal_triangle(n, 2), 5);
  int checked = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double sx = screen(x, n), sy = -screen(y, n);
      if (sx + sy > -0.1) continue;  // keep clear of the hypotenuse (x + y = 0)
      INFO("pixel " << x << "," << y);
      const std::size_t i = static_cast<std::size_t>(y) * n + x;
      // The hit P = (10 sx, 10 sy, 0) has barycentrics u = (Px + 10) / 20 (towards b) and
      // v = (Py + 10) / 20 (towards c).
      const Vec3d p{10 * sx, 10 * sy, 0};
      const double u = (p.x + 10) / 20, v = (p.y + 10) / 20;
      const Vec3d ns = glm::normalize(Vec3d(0, 0, 1) * (1 - u - v) + glm::normalize(Vec3d(1, 0, 2)) * u +
                                      glm::normalize(Vec3d(0, 1, 2)) * v);
      const Vec3d l = glm::normalize(light - p);
      const Vec3d want = kd * std::max(0.0, dot3(ns, l));
      const Vec3d want_flat = kd * std::max(0.0, l.z);
      REQUIRE(smooth.image.object[i] == 0);
      CHECK(smooth.image.r[i] == Approx(want.x).epsilon(2e-5));
      CHECK(smooth.image.g[i] == Approx(want.y).epsilon(2e-5));
      CHECK(smooth.image.b[i] == Approx(want.z).epsilon(2e-5));
      CHECK(flat.image.r[i] == Approx(want_flat.x).epsilon(2e-5));
      CHECK(flat.image.b[i] == Approx(want_flat.z).epsilon(2e-5));
      // The interpolated normal differs from the face's by enough to show.
      CHECK(std::abs(smooth.image.b[i] - flat.image.b[i]) > 1e-3);
      ++checked;
    }
  CHECK(checked > 50);
  // Published normals equal to the face's own give the flat image, bit for bit, every pixel.
  CHECK(face.image.r == flat.image.r);
  CHECK(face.image.g == flat.image.g);
  CHECK(face.image.b == flat.image.b);
  CHECK(face.image.z == flat.image.z);
  // Without reflecting or transmitting materials the depth bound changes nothing.
  const FrameResult flat0 = render<TestType>(normal_triangle(n, 0), 0);
  CHECK(flat0.image.r == flat.image.r);
  CHECK(flat0.image.b == flat.image.b);
  CHECK(flat0.work.rays == flat.work.rays);
}
