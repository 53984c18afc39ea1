#include "scene/generate.h"
#include "scene/json_vec.h"

#include <cmath>
#include <random>

namespace oprt {

namespace {
constexpr double kPi = 3.14159265358979323846;

// splitmix64: a fixed, portable generator (std::uniform_real_distribution is not
// specified bit for bit across standard libraries; this is).
struct SplitMix {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return (next() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
  double symmetric() { return 2 * uniform() - 1; }                          // [-1, 1)
};

std::uint32_t add_vertex(Mesh& m, const Vec3d& v) {
  m.vertices.push_back(v);
  return static_cast<std::uint32_t>(m.vertices.size() - 1);
}
}  // namespace

Mesh triangle_cloud(std::uint32_t count, double radius, double size, std::uint64_t seed) {
  SplitMix rng{seed};
  Mesh m;
  m.vertices.reserve(3 * count);
  m.triangles.reserve(count);
  auto in_ball = [&](double r) {
    Vec3d p;
    do p = {rng.symmetric(), rng.symmetric(), rng.symmetric()};
    while (dot3(p, p) > 1);
    return p * r;
  };
  for (std::uint32_t i = 0; i < count; ++i) {
    const Vec3d c = in_ball(radius - size);
    Tri t;
    for (int k = 0; k < 3; ++k) t[k] = add_vertex(m, c + in_ball(size));
    m.triangles.push_back(t);
  }
  return m;
}

Mesh plane(double width, double depth, std::uint32_t nx, std::uint32_t nz) {
  Mesh m;
  for (std::uint32_t j = 0; j <= nz; ++j)
    for (std::uint32_t i = 0; i <= nx; ++i)
      add_vertex(m, {width * (double(i) / nx - 0.5), 0, depth * (double(j) / nz - 0.5)});
  for (std::uint32_t j = 0; j < nz; ++j)
    for (std::uint32_t i = 0; i < nx; ++i) {
      const std::uint32_t a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      m.triangles.push_back({a, c, b});  // counter-clockwise seen from +y
      m.triangles.push_back({b, c, d});
    }
  return m;
}

Mesh box(const Vec3d& size, std::uint32_t n) {
  Mesh m;
  const Vec3d h = size * 0.5;
  // Each face: a plane grid rotated into place. Axes: (u, v, normal).
  struct Face { Vec3d u, v, n; };
  const Face faces[6] = {{{0, 0, 1}, {0, 1, 0}, {1, 0, 0}},  {{0, 0, -1}, {0, 1, 0}, {-1, 0, 0}},
                         {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},  {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
                         {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}};
  for (const Face& f : faces) {
    const std::uint32_t base = static_cast<std::uint32_t>(m.vertices.size());
    for (std::uint32_t j = 0; j <= n; ++j)
      for (std::uint32_t i = 0; i <= n; ++i) {
        const double s = double(i) / n * 2 - 1, t = double(j) / n * 2 - 1;
        const Vec3d p = f.n + f.u * s + f.v * t;
        add_vertex(m, p * h);
      }
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({b, d, c});
      }
  }
  return m;
}

Mesh uv_sphere(double radius, std::uint32_t segments, std::uint32_t rings) {
  Mesh m;
  const std::uint32_t top = add_vertex(m, {0, radius, 0});
  for (std::uint32_t r = 1; r < rings; ++r) {
    const double th = kPi * r / rings;
    for (std::uint32_t s = 0; s < segments; ++s) {
      const double ph = 2 * kPi * s / segments;
      add_vertex(m, {radius * std::sin(th) * std::cos(ph), radius * std::cos(th),
                     -radius * std::sin(th) * std::sin(ph)});
    }
  }
  const std::uint32_t bottom = add_vertex(m, {0, -radius, 0});
  auto ring = [&](std::uint32_t r, std::uint32_t s) { return 1 + (r - 1) * segments + s % segments; };
  for (std::uint32_t s = 0; s < segments; ++s) m.triangles.push_back({top, ring(1, s), ring(1, s + 1)});
  for (std::uint32_t r = 1; r + 1 < rings; ++r)
    for (std::uint32_t s = 0; s < segments; ++s) {
      m.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      m.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
  for (std::uint32_t s = 0; s < segments; ++s)
    m.triangles.push_back({bottom, ring(rings - 1, s + 1), ring(rings - 1, s)});
  return m;
}

Mesh cylinder(double radius, double height, std::uint32_t segments, bool caps) {
  Mesh m;
  for (std::uint32_t s = 0; s < segments; ++s) {
    const double ph = 2 * kPi * s / segments;
    add_vertex(m, {radius * std::cos(ph), 0, -radius * std::sin(ph)});
    add_vertex(m, {radius * std::cos(ph), height, -radius * std::sin(ph)});
  }
  for (std::uint32_t s = 0; s < segments; ++s) {
    const std::uint32_t a = 2 * s, b = a + 1, c = 2 * ((s + 1) % segments), d = c + 1;
    m.triangles.push_back({a, c, b});
    m.triangles.push_back({b, c, d});
  }
  if (caps) {
    const std::uint32_t lo = add_vertex(m, {0, 0, 0}), hi = add_vertex(m, {0, height, 0});
    for (std::uint32_t s = 0; s < segments; ++s) {
      const std::uint32_t a = 2 * s, c = 2 * ((s + 1) % segments);
      m.triangles.push_back({lo, c, a});
      m.triangles.push_back({hi, a + 1, c + 1});
    }
  }
  return m;
}

Mesh torus(double major, double minor, std::uint32_t segments, std::uint32_t sides) {
  Mesh m;
  for (std::uint32_t i = 0; i < segments; ++i) {
    const double u = 2 * kPi * i / segments;
    for (std::uint32_t j = 0; j < sides; ++j) {
      const double v = 2 * kPi * j / sides;
      const double r = major + minor * std::cos(v);
      add_vertex(m, {r * std::cos(u), minor * std::sin(v), -r * std::sin(u)});
    }
  }
  auto at = [&](std::uint32_t i, std::uint32_t j) { return (i % segments) * sides + j % sides; };
  for (std::uint32_t i = 0; i < segments; ++i)
    for (std::uint32_t j = 0; j < sides; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

Mesh lathe(const std::vector<std::pair<double, double>>& profile, std::uint32_t segments, bool cap_first,
           bool cap_last) {
  Mesh m;
  const std::uint32_t n = static_cast<std::uint32_t>(profile.size());
  for (const auto& [r, y] : profile)
    for (std::uint32_t s = 0; s < segments; ++s) {
      const double ph = 2 * kPi * s / segments;
      add_vertex(m, {r * std::cos(ph), y, -r * std::sin(ph)});
    }
  auto at = [&](std::uint32_t i, std::uint32_t s) { return i * segments + s % segments; };
  for (std::uint32_t i = 0; i + 1 < n; ++i)
    for (std::uint32_t s = 0; s < segments; ++s) {
      m.triangles.push_back({at(i, s), at(i, s + 1), at(i + 1, s)});
      m.triangles.push_back({at(i + 1, s), at(i, s + 1), at(i + 1, s + 1)});
    }
  auto cap = [&](std::uint32_t i, bool flip) {
    const std::uint32_t c = add_vertex(m, {0, profile[i].second, 0});
    for (std::uint32_t s = 0; s < segments; ++s)
      m.triangles.push_back(flip ? Tri{c, at(i, s + 1), at(i, s)} : Tri{c, at(i, s), at(i, s + 1)});
  };
  if (cap_first) cap(0, true);
  if (cap_last) cap(n - 1, false);
  return m;
}

Mesh generate_from_json(const JsonIn& g, std::uint64_t max_triangles) {
  MeshBudget budget(max_triangles);
  return generate_from_json(g, budget);
}

Mesh generate_from_json(const JsonIn& g, MeshBudget& budget) {
  const std::string kind = g.at("kind").string();
  auto count = [&](const char* key, long long lo, long long def) {
    return static_cast<std::uint32_t>(g.integer_or(key, def, lo, 1 << 24));
  };
  auto positive = [&](const char* key, double def) { return g.number_or(key, def, 1e-30, 1e30); };
  // The closed formulas of generate.h, in 64 bits (each factor is below 2^24).
  auto affordable = [&](std::uint64_t triangles, std::uint64_t vertices) {
    budget.charge(g.file(), g.place(), "this generator", vertices, triangles);
  };
  using U = std::uint64_t;
  if (kind == "triangle_cloud") {
    g.only_keys({"kind", "count", "radius", "size", "seed"});
    const double radius = positive("radius", 1), size = positive("size", 0.1);
    if (!(size < radius)) g.at("size").fail("size must be smaller than radius");
    const std::uint32_t n = count("count", 1, 1024);
    affordable(n, 3 * U(n));
    return triangle_cloud(n, radius, size, static_cast<std::uint64_t>(g.integer_or("seed", 1, 0, 1LL << 62)));
  }
  if (kind == "box") {
    g.only_keys({"kind", "size", "divisions"});
    const Vec3d s = vec3_or(g, "size", Vec3d(1));
    if (!(s.x > 0 && s.y > 0 && s.z > 0)) g.at("size").fail("box sizes must be positive");
    const std::uint32_t n = count("divisions", 1, 1);
    affordable(12 * U(n) * n, 6 * U(n + 1) * (n + 1));
    return box(s, n);
  }
  if (kind == "sphere") {
    g.only_keys({"kind", "radius", "segments", "rings"});
    const double r = positive("radius", 1);
    const std::uint32_t segments = count("segments", 3, 16), rings = count("rings", 2, 8);
    affordable(2 * U(segments) * (rings - 1), U(segments) * (rings - 1) + 2);
    return uv_sphere(r, segments, rings);
  }
  if (kind == "cylinder") {
    g.only_keys({"kind", "radius", "height", "segments", "caps"});
    const double r = positive("radius", 1), h = positive("height", 1);
    const std::uint32_t segments = count("segments", 3, 16);
    const bool caps = g.boolean_or("caps", true);
    affordable((caps ? 4 : 2) * U(segments), 2 * U(segments) + (caps ? 2 : 0));
    return cylinder(r, h, segments, caps);
  }
  if (kind == "torus") {
    g.only_keys({"kind", "major", "minor", "segments", "sides"});
    const double major = positive("major", 1), minor = positive("minor", 0.25);
    const std::uint32_t segments = count("segments", 3, 32), sides = count("sides", 3, 12);
    affordable(2 * U(segments) * sides, U(segments) * sides);
    return torus(major, minor, segments, sides);
  }
  if (kind == "plane") {
    g.only_keys({"kind", "width", "depth", "nx", "nz"});
    const double w = positive("width", 1), d = positive("depth", 1);
    const std::uint32_t nx = count("nx", 1, 1), nz = count("nz", 1, 1);
    affordable(2 * U(nx) * nz, U(nx + 1) * (nz + 1));
    return plane(w, d, nx, nz);
  }
  if (kind == "lathe") {
    g.only_keys({"kind", "profile", "segments", "cap_first", "cap_last"});
    std::vector<std::pair<double, double>> profile;
    for (const JsonIn& p : g.at("profile").items()) {
      const auto ry = p.items();
      if (ry.size() != 2) p.fail("a profile point is [r, y], found " + std::to_string(ry.size()) + " numbers");
      profile.emplace_back(ry[0].number(1e-30, 1e30), ry[1].number());
    }
    if (profile.size() < 2) g.at("profile").fail("a lathe profile needs at least 2 points");
    const std::uint32_t segments = count("segments", 3, 16);
    const bool first = g.boolean_or("cap_first", false), last = g.boolean_or("cap_last", false);
    affordable(U(segments) * (2 * (profile.size() - 1) + first + last), U(segments) * profile.size() + first + last);
    return lathe(profile, segments, first, last);
  }
  g.at("kind").fail("unknown generator \"" + kind +
                    "\" (expected triangle_cloud, box, sphere, cylinder, torus, plane or lathe)");
}

}  // namespace oprt
