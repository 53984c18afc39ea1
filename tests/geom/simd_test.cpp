// The SIMD kernels (geom/simd_kernels.h) against the scalar ones, field by field and bit for
// bit, through the block functions and the sphere test as the engine calls them: seeded
// random rays and triangles with the hard features built in (shared edges and vertices hit
// exactly, zero-area triangles, rays parallel to the plane or in it, t exactly at tmax,
// triangles behind the origin, magnitudes from float's denormals to its overflow), both
// kernels, both precisions, nearest and any hit, with and without the exit-stage log, on
// blocks of every length from 0 to 3 W + 1 at every offset modulo W.
#include "geom/sphere_soa.h"
#include "geom/triangle_soa.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

using namespace oprt;

namespace {

using Rng = std::mt19937_64;

double uniform(Rng& r, double a, double b) { return std::uniform_real_distribution<double>(a, b)(r); }
Vec3d random_unit(Rng& r) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3d v(n(r), n(r), n(r));
    const double l = std::sqrt(dot3(v, v));
    if (l > 1e-6) return v / l;
  }
}

// Sets the SIMD mode for a scope.
struct Mode {
  SimdMode before = simd_mode();
  explicit Mode(SimdMode m) { set_simd_mode(m); }
  ~Mode() { set_simd_mode(before); }
};

template <typename T>
bool same_bits(T a, T b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// A triangle soup at scale s: a grid of squares in the plane z = 0 with vertices on exact
// multiples of 1/4 (so axis-aligned rays through grid points give edge functions of exactly
// 0, and neighbours share edges and vertices bit for bit), some of its vertices lifted off
// the plane, zero-area triangles, and random triangles around it.
struct Soup {
  std::vector<Vec3d> tris;  // 3 per triangle
  std::vector<Vec3d> points;  // grid points and vertices to aim at
  double scale = 1;
};

Soup make_soup(Rng& rng, double s) {
  Soup soup;
  soup.scale = s;
  constexpr int kGrid = 4;
  auto grid = [&](int i, int j, bool lift) {
    return Vec3d(0.25 * i - 0.5, 0.25 * j - 0.5, lift ? 0.125 * ((i + j) % 3) : 0.0) * s;
  };
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const bool lift = (i + j) % 4 == 3;
      const Vec3d a = grid(i, j, lift), b = grid(i + 1, j, lift);
      const Vec3d c = grid(i + 1, j + 1, lift), d = grid(i, j + 1, lift);
      if ((i * 7 + j) % 2) {
        soup.tris.insert(soup.tris.end(), {a, b, c, a, c, d});
      } else {
        soup.tris.insert(soup.tris.end(), {b, c, d, d, a, b});  // the other diagonal, other orientation
      }
      soup.points.push_back(a);
      soup.points.push_back((a + c) * 0.5);
    }
  // Zero-area: collinear, a repeated vertex, a single point.
  const Vec3d p = grid(1, 1, false), q = grid(3, 2, false);
  soup.tris.insert(soup.tris.end(), {p, (p + q) * 0.5, q, p, p, q, q, q, q});
  for (int k = 0; k < 9; ++k)
    soup.tris.push_back(Vec3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -0.5, 0.5)) * s);
  return soup;
}

template <typename T>
TriangleStore<T> store_of(const Soup& soup, Kernel k) {
  TriangleStore<T> m(k);
  for (std::size_t i = 0; i < soup.tris.size(); i += 3) m.push_back(soup.tris[i], soup.tris[i + 1], soup.tris[i + 2]);
  return m;
}

// Rays of every kind the soup is built for.
template <typename T>
std::vector<Ray<T>> make_rays(Rng& rng, const Soup& soup, int count) {
  std::vector<Ray<T>> rays;
  const double s = soup.scale;
  for (int i = 0; i < count; ++i) {
    Vec3d o, d;
    const Vec3d target = soup.points[rng() % soup.points.size()];
    switch (i % 6) {
      case 0:  // random
        o = Vec3d(uniform(rng, -2, 2), uniform(rng, -2, 2), uniform(rng, -2, 2)) * s;
        d = random_unit(rng);
        break;
      case 1:  // at a grid point or a vertex, from anywhere
        o = target + random_unit(rng) * (s * uniform(rng, 0.5, 3));
        d = glm::normalize(target - o);
        break;
      case 2:  // along the axes through grid points: edge functions exactly zero
        o = target;
        o.z = (i % 12 < 6 ? 2.0 : -2.0) * s;
        d = Vec3d(0, 0, o.z > 0 ? -1 : 1);
        break;
      case 3:  // parallel to the grid's plane, or in it
        o = Vec3d(uniform(rng, -2, 2), uniform(rng, -2, 2), i % 12 < 6 ? 0.0 : uniform(rng, -0.2, 0.2)) * s;
        d = glm::normalize(Vec3d(uniform(rng, -1, 1), uniform(rng, -1, 1), 0));
        break;
      case 4:  // away from the soup: every t negative
        o = target + Vec3d(0, 0, s);
        d = glm::normalize(Vec3d(uniform(rng, -0.3, 0.3), uniform(rng, -0.3, 0.3), 1));
        break;
      default:  // axis-aligned along x or y through grid lines
        o = target;
        if (i % 12 < 6) o.x = -2 * s, d = Vec3d(1, 0, 0);
        else o.y = 2 * s, d = Vec3d(0, -1, 0);
        o.z = 0;
        break;
    }
    rays.push_back({Vec3<T>(o), Vec3<T>(d), kInf<T>});
  }
  return rays;
}

// One block call's outputs; counters and log start from non-zero garbage that both paths
// must add to (counts) or leave alone (log entries past the tests made, and past the block).
struct Outputs {
  std::uint64_t stages[kTriStages] = {5, 6, 7, 8}, hits = 9;
  std::vector<std::uint8_t> log;
  explicit Outputs(std::size_t n) : log(n + 8, 0xEE) {}
};

template <typename T>
void compare_block(const TriangleStore<T>& m, std::uint32_t first, std::uint32_t end, const Ray<T>& ray) {
  for (bool logged : {false, true}) {
    Outputs a(end - first), b(end - first);
    BlockHit<T> ha, hb;
    {
      const Mode off(SimdMode::off);
      ha = nearest_in_block(m, first, end, ray, a.stages, &a.hits, logged ? a.log.data() : nullptr);
    }
    {
      const Mode on(SimdMode::on);
      hb = nearest_in_block(m, first, end, ray, b.stages, &b.hits, logged ? b.log.data() : nullptr);
    }
    CHECK(ha.index == hb.index);
    CHECK(same_bits(ha.t, hb.t));
    CHECK(same_bits(ha.u, hb.u));
    CHECK(same_bits(ha.v, hb.v));
    for (int s = 0; s < kTriStages; ++s) CHECK(a.stages[s] == b.stages[s]);
    CHECK(a.hits == b.hits);
    CHECK(a.log == b.log);

    Outputs c(end - first), d(end - first);
    bool oc, od;
    {
      const Mode off(SimdMode::off);
      oc = any_in_block(m, first, end, ray, c.stages, &c.hits, logged ? c.log.data() : nullptr);
    }
    {
      const Mode on(SimdMode::on);
      od = any_in_block(m, first, end, ray, d.stages, &d.hits, logged ? d.log.data() : nullptr);
    }
    CHECK(oc == od);
    for (int s = 0; s < kTriStages; ++s) CHECK(c.stages[s] == d.stages[s]);
    CHECK(c.hits == d.hits);
    CHECK(c.log == d.log);
  }
}

// How many block calls found a hit, and how many tests exited at each stage (so that the
// test can show it reached every stage and the hard paths).
struct Coverage {
  std::uint64_t stages[kTriStages] = {}, hits = 0, ties = 0;
};

template <typename T>
Coverage compare_soup(Rng& rng, double scale, Kernel k, int rays) {
  const Soup soup = make_soup(rng, scale);
  const TriangleStore<T> m = store_of<T>(soup, k);
  const std::uint32_t n = static_cast<std::uint32_t>(m.size());
  constexpr std::uint32_t W = kLanes<T>;
  Coverage cov;
  for (Ray<T> ray : make_rays<T>(rng, soup, rays)) {
    for (int pass = 0; pass < 2; ++pass) {
      // Every length 0 .. 3W + 1 at offsets 0 .. W, and the whole store.
      for (std::uint32_t first = 0; first <= W; ++first)
        for (std::uint32_t len = 0; len <= 3 * W + 1 && first + len <= n; ++len)
          compare_block(m, first, first + len, ray);
      compare_block(m, 0, n, ray);
      // Coverage, and the second pass with tmax exactly at the nearest hit's t (rejected there).
      const Mode off(SimdMode::off);
      std::uint64_t stages[kTriStages] = {}, hits = 0;
      const BlockHit<T> h = nearest_in_block(m, 0, n, ray, stages, &hits);
      for (int s = 0; s < kTriStages; ++s) cov.stages[s] += stages[s];
      cov.hits += hits;
      if (!h.valid() || pass == 1) break;
      ray.tmax = h.t;
    }
  }
  return cov;
}

template <typename T>
void compare_kernels(Kernel k) {
  if (!simd_available()) WARN("this build has no SIMD kernels (no AVX2): the scalar path is compared with itself");
  Rng rng(k == Kernel::watertight ? 21 : 22);
  // Scales: float denormal products, small, unit, large, and (in float) overflowing products.
  for (double scale : {1e-22, 1e-3, 1.0, 1e3, 1e17, 1e21}) {
    INFO("scale " << scale);
    const Coverage cov = compare_soup<T>(rng, scale, k, 60);
    if (scale == 1.0) {
      for (int s = 0; s < kTriStages; ++s) CHECK(cov.stages[s] > 0);  // every stage reached
      CHECK(cov.hits > 0);
    }
  }
}

}  // namespace

TEMPLATE_TEST_CASE("simd: Moller-Trumbore blocks give the scalar kernel's results bit for bit", "[simd]", float,
                   double) {
  compare_kernels<TestType>(Kernel::moller);
}

TEMPLATE_TEST_CASE("simd: watertight blocks give the scalar kernel's results bit for bit", "[simd]", float, double) {
  compare_kernels<TestType>(Kernel::watertight);
}

// The watertight kernel's exact fallback runs per lane: a chunk where some lanes' edge
// functions round to exactly 0 and others' do not, next to a chunk where all do.
TEMPLATE_TEST_CASE("simd: watertight edge functions of exactly zero in some lanes", "[simd]", float, double) {
  using T = TestType;
  TriangleStore<T> m(Kernel::watertight);
  // Around the point (0, 0): four triangles sharing the vertex, four sharing only an edge
  // through it, and alternating with them triangles far away; then zero-area ones.
  const Vec3d o(0, 0, 1);
  const Vec3d ring[4] = {{1, 0, 1}, {0, 1, 1}, {-1, 0, 1}, {0, -1, 1}};
  for (int i = 0; i < 4; ++i) {
    m.push_back(o, ring[i], ring[(i + 1) % 4]);
    m.push_back(ring[i] + Vec3d(5, 5, 0), ring[(i + 1) % 4] + Vec3d(5, 5, 0), o + Vec3d(5, 5, 0));
    m.push_back(ring[i], ring[(i + 1) % 4], ring[(i + 2) % 4]);
  }
  for (int i = 0; i < 5; ++i) m.push_back(o, o, o);
  const std::uint32_t n = static_cast<std::uint32_t>(m.size());
  std::uint64_t stages[kTriStages] = {}, hits = 0;
  for (const Ray<T>& ray : {Ray<T>{{0, 0, 0}, {0, 0, 1}, kInf<T>}, Ray<T>{{0, 0, 2}, {0, 0, -1}, kInf<T>},
                            Ray<T>{{0.5, 0, 0}, {0, 0, 1}, kInf<T>}, Ray<T>{{0, -0.5, 2}, {0, 0, -1}, kInf<T>}}) {
    for (std::uint32_t first = 0; first < kLanes<T>; ++first) compare_block(m, first, n, ray);
    const Mode off(SimdMode::off);
    nearest_in_block(m, 0, n, ray, stages, &hits);
  }
  CHECK(hits >= 4);  // each ray hits: the vertex and the edges have one owner (at least)
  CHECK(stages[static_cast<int>(WtStage::det)] > 0);
}

// Spheres: random, hit through their centres, grazed along a tangent (|l|^2 within a few
// ulps of r^2, where the order of the additions decides), tiny and far (1e-3 at 1e5),
// origins inside and exactly on the surface, zero radius; every count 1 .. W at every offset.
TEMPLATE_TEST_CASE("simd: the sphere test over a unit's spheres gives hit_sphere's answers", "[simd]", float, double) {
  using T = TestType;
  Rng rng(23);
  std::vector<Sphere<T>> spheres;
  SphereSoA<T> soa;
  std::vector<Ray<T>> rays;
  for (int i = 0; i < 40; ++i) {
    const double dist = std::pow(10.0, uniform(rng, 0, 5)), r = std::pow(10.0, uniform(rng, -3, 1));
    const Vec3d c = random_unit(rng) * dist;
    Sphere<T> s{Vec3<T>(c), static_cast<T>(i % 13 == 0 ? 0.0 : r)};
    spheres.push_back(s);
    soa.push_back(s);
  }
  for (int i = 0; i < 3000; ++i) {
    const Sphere<T>& s = spheres[rng() % spheres.size()];
    const Vec3d c(s.c);
    const double r = static_cast<double>(s.r);
    Vec3d o = random_unit(rng) * uniform(rng, 0, 10), d;
    switch (i % 5) {
      case 0:  // through the sphere
        d = glm::normalize(c + random_unit(rng) * (r * uniform(rng, 0, 1.2)) - o);
        break;
      case 1:  // from inside
        o = c + random_unit(rng) * (r * uniform(rng, 0, 1));
        d = random_unit(rng);
        break;
      case 2:  // from the surface, perpendicular to the radius there
        o = c + Vec3d(r, 0, 0);
        d = glm::normalize(Vec3d(0, uniform(rng, -1, 1), uniform(rng, -1, 1)));
        break;
      case 3: {  // along a tangent
        const Vec3d to_c = glm::normalize(c - o);
        const Vec3d side = glm::normalize(cross3(to_c, random_unit(rng)));
        const double sin_a = std::min(1.0, r / std::sqrt(dot3(c - o, c - o)));
        d = to_c * std::sqrt(1 - sin_a * sin_a) + side * sin_a;
        break;
      }
      default:  // away from it
        d = -glm::normalize(c - o);
        break;
    }
    rays.push_back({Vec3<T>(o), Vec3<T>(d), kInf<T>});
  }
  std::uint64_t hit = 0, tested = 0;
  for (const Ray<T>& ray : rays)
    for (std::size_t i = 0; i <= kLanes<T>; ++i)
      for (unsigned n = 1; n <= kLanes<T> && i + n <= spheres.size(); ++n) {
        unsigned a, b;
        {
          const Mode off(SimdMode::off);
          a = sphere_hits(spheres, soa, ray, i, n);
        }
        {
          const Mode on(SimdMode::on);
          b = sphere_hits(spheres, soa, ray, i, n);
        }
        CHECK(a == b);
        unsigned expect = 0;
        for (unsigned j = 0; j < n; ++j) expect |= static_cast<unsigned>(hit_sphere(ray, spheres[i + j])) << j;
        CHECK(a == expect);
        hit += static_cast<unsigned>(__builtin_popcount(a));
        tested += n;
      }
  CHECK(hit > 0);  // both outcomes occur
  CHECK(hit < tested);
}

// Tangent rays in bulk, near the origin where T keeps the tangency to a few ulps: the
// outcome turns on the last bits of |l|^2 against r^2.
TEMPLATE_TEST_CASE("simd: the sphere test on tangent rays", "[simd]", float, double) {
  using T = TestType;
  Rng rng(24);
  std::vector<Sphere<T>> spheres;
  SphereSoA<T> soa;
  for (int i = 0; i < 8; ++i) {
    const Sphere<T> s{Vec3<T>(random_unit(rng) * uniform(rng, 0, 4)), static_cast<T>(uniform(rng, 0.1, 3))};
    spheres.push_back(s);
    soa.push_back(s);
  }
  std::uint64_t hit = 0, tested = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d o = random_unit(rng) * uniform(rng, 8, 12);
    const Sphere<T>& s = spheres[i % spheres.size()];
    const Vec3d c(s.c), to_c = glm::normalize(c - o);
    const Vec3d side = glm::normalize(cross3(to_c, random_unit(rng)));
    const double sin_a = static_cast<double>(s.r) / std::sqrt(dot3(c - o, c - o));  // the line at distance r from c
    const Ray<T> ray{Vec3<T>(o), Vec3<T>(to_c * std::sqrt(1 - sin_a * sin_a) + side * sin_a), kInf<T>};
    unsigned a, b;
    {
      const Mode off(SimdMode::off);
      a = sphere_hits(spheres, soa, ray, 0, kLanes<T>);
    }
    {
      const Mode on(SimdMode::on);
      b = sphere_hits(spheres, soa, ray, 0, kLanes<T>);
    }
    CHECK(a == b);
    hit += (a >> (i % spheres.size()) & 1u);
    ++tested;
  }
  CHECK(hit > tested / 10);  // about half the tangents enter
  CHECK(hit < tested - tested / 10);
}

TEST_CASE("simd: the mode can be set, and means off in a build without the SIMD kernels", "[simd]") {
  const Mode scope(SimdMode::check);
  CHECK(simd_mode() == (simd_available() ? SimdMode::check : SimdMode::off));
  set_simd_mode(SimdMode::off);
  CHECK(simd_mode() == SimdMode::off);
  CHECK(std::string(to_string(SimdMode::on)) == "on");
}
