// The BVH's pieces on their own: the box test against exact arithmetic (it must never reject
// a box the exact ray segment meets), and the builder's invariants (a partition of the
// triangles into contiguous leaves, boxes that hold their subtrees).
#include "geom/bvh.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <random>

using namespace oprt;

namespace {

template <typename T>
Box<T> box(T x0, T y0, T z0, T x1, T y1, T z1) {
  Box<T> b;
  b.lo = {x0, y0, z0};
  b.hi = {x1, y1, z1};
  return b;
}

// An exact rational p / q, q > 0.
struct Rational {
  long long p, q;
};
bool less_eq(const Rational& a, const Rational& b) { return a.p * b.q <= b.p * a.q; }
// a <= x for a dyadic x (a T value): q x is exact in long double for the small q used here.
bool less_eq(const Rational& a, long double x) { return static_cast<long double>(a.p) <= x * a.q; }

// Does the exact segment o + t d, t in [0, limit], meet the closed integer box?
bool exact_meets(const int o[3], const int d[3], const int lo[3], const int hi[3], long double limit, bool& touching) {
  Rational t0{0, 1}, t1{1, 0};  // t1 = +inf until an axis or the limit bounds it
  bool t1_finite = false;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    Rational n{lo[a] - o[a], d[a]}, f{hi[a] - o[a], d[a]};
    if (d[a] < 0) {
      n = {o[a] - hi[a], -d[a]};
      f = {o[a] - lo[a], -d[a]};
    }
    if (!less_eq(n, t0)) t0 = n;
    if (!t1_finite || less_eq(f, t1)) t1 = f, t1_finite = true;
  }
  if (!less_eq(t0, limit)) return false;
  if (t1_finite && !less_eq(t0, t1)) return false;
  touching = t1_finite && t0.p * t1.q == t1.p * t0.q;
  return true;
}

// Every node of a tree: calls f(index, depth).
void walk(const BvhBuild& b, const std::function<void(std::uint32_t, int)>& f, std::uint32_t i = 0, int depth = 0) {
  f(i, depth);
  if (b.nodes[i].leaf()) return;
  walk(b, f, i + 1, depth + 1);
  walk(b, f, b.nodes[i].offset, depth + 1);
}

// The leaves' triangles, in depth-first order, must be `order` in sequence.
void check_tree(const BvhBuild& b, const std::vector<Box<double>>& tris, int max_leaf) {
  REQUIRE_FALSE(b.nodes.empty());
  std::vector<std::uint32_t> sorted = b.order;
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t i = 0; i < sorted.size(); ++i) REQUIRE(sorted[i] == i);  // a permutation
  REQUIRE(sorted.size() == tris.size());
  std::uint32_t next = 0;  // leaf ranges follow each other in depth-first order
  std::vector<Box<double>> subtree(b.nodes.size());
  walk(b, [&](std::uint32_t i, int depth) {
    const BvhNode<double>& n = b.nodes[i];
    CHECK(depth < b.depth);
    if (!n.leaf()) {
      CHECK(n.offset > i + 1);
      CHECK(n.offset < b.nodes.size());
      return;
    }
    CHECK(n.offset == next);
    CHECK(n.count <= max_leaf);
    next += n.count;
    for (std::uint32_t k = n.offset; k < n.offset + n.count; ++k) {
      CHECK(n.box.contains(tris[b.order[k]]));
      if (k > n.offset) CHECK(b.order[k - 1] < b.order[k]);  // ascending: ties to the lowest prim
    }
  });
  CHECK(next == tris.size());
  // Every interior box holds its children's.
  for (std::uint32_t i = 0; i < b.nodes.size(); ++i)
    if (!b.nodes[i].leaf()) {
      CHECK(b.nodes[i].box.contains(b.nodes[i + 1].box));
      CHECK(b.nodes[i].box.contains(b.nodes[b.nodes[i].offset].box));
    }
}

std::vector<Box<double>> random_triangles(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> pos(-10, 10), size(0.01, 2);
  std::vector<Box<double>> out;
  for (int i = 0; i < n; ++i) {
    const Vec3d c(pos(rng), pos(rng), pos(rng));
    const double s = size(rng);
    Box<double> b;
    b.extend(c);
    b.extend(c + Vec3d(s, 0, 0));
    b.extend(c + Vec3d(0, i % 3 == 0 ? 0 : s, s));  // a third of them flat in y
    out.push_back(b);
  }
  return out;
}

}  // namespace

TEMPLATE_TEST_CASE("bvh: box test by hand", "[bvh]", float, double) {
  using T = TestType;
  const Box<T> unit = box<T>(0, 0, 0, 1, 1, 1);
  auto hit = [&](Vec3<T> o, Vec3<T> d, T limit, const Box<T>& b) {
    return hit_box(box_ray(Ray<T>{o, d, kInf<T>}), b, limit);
  };
  CHECK(hit({T(0.5), T(0.5), -2}, {0, 0, 1}, kInf<T>, unit));       // straight through, enters at t = 2
  CHECK(hit({T(0.5), T(0.5), -2}, {0, 0, 1}, 2, unit));              // limit exactly the entry: kept
  CHECK_FALSE(hit({T(0.5), T(0.5), -2}, {0, 0, 1}, T(1.5), unit));   // limit clearly before the entry
  CHECK_FALSE(hit({T(0.5), T(0.5), 2}, {0, 0, 1}, kInf<T>, unit));   // box behind the origin
  CHECK(hit({T(0.5), T(0.5), T(0.5)}, {1, 2, 3}, kInf<T>, unit));    // origin inside
  CHECK_FALSE(hit({2, T(0.5), -2}, {0, 0, 1}, kInf<T>, unit));       // parallel to z, beside the box
  // Direction component exactly zero with the origin on the slab's plane: 0 * inf = NaN,
  // which must not reject (the ray runs along the face).
  CHECK(hit({1, T(0.5), -2}, {0, 0, 1}, kInf<T>, unit));
  CHECK(hit({0, 0, -2}, {0, 0, 1}, kInf<T>, unit));                  // along an edge
  CHECK(hit({T(0.5), T(0.5), -2}, {T(-0.0), 0, 1}, kInf<T>, unit));  // -0 component
  // A flat box (a floor: lo.y == hi.y) is hit from above and missed by a ray above it.
  const Box<T> floor = box<T>(-1, 0, -1, 1, 0, 1);
  CHECK(hit({0, 1, 0}, {T(0.1), -1, 0}, kInf<T>, floor));
  CHECK_FALSE(hit({0, 1, 0}, {1, 0, 0}, kInf<T>, floor));
  // Through a corner exactly: the segment meets the box in one point.
  CHECK(hit({-1, 2, T(0.5)}, {1, -1, 0}, kInf<T>, unit));
  // The slack (1 + 8u in float) exceeds 1 + gamma(7), computed exactly enough in long double.
  const long double u = unit_roundoff<T>();
  CHECK(static_cast<long double>(kBoxSlack<T>) > 1 + 7 * u / (1 - 7 * u));
  CHECK(static_cast<long double>(kBoxSlack<T>) < 1 + 9 * u / (1 - 9 * u));
}

TEMPLATE_TEST_CASE("bvh: the box test never rejects a box the exact segment meets", "[bvh][hard]", float, double) {
  using T = TestType;
  std::mt19937_64 rng(4242);
  // Odd directions and large coordinates: slab distances that are equal as rationals but
  // computed through different reciprocals (1/7 and 1/3 round differently).
  std::uniform_int_distribution<int> coord(-300, 300), dir(-61, 61), step(1, 40), pick(0, 9);
  int meets = 0, touching = 0, ties = 0, misses = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    int lo[3], hi[3], o[3], d[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = coord(rng);
      hi[a] = lo[a] + (pick(rng) < 2 ? 0 : 5 * step(rng));  // some flat boxes
      d[a] = dir(rng);
    }
    if (!d[0] && !d[1] && !d[2]) continue;
    // Half the rays are aimed exactly through a corner, edge point or face point of the box:
    // the touching cases where the computed test is most likely to err.
    if (pick(rng) < 5) {
      int p[3];
      for (int a = 0; a < 3; ++a) p[a] = pick(rng) < 4 ? lo[a] : pick(rng) < 6 ? hi[a] : (lo[a] + hi[a]) / 2;
      const int k = step(rng);
      for (int a = 0; a < 3; ++a) o[a] = p[a] - k * d[a];
    } else {
      for (int a = 0; a < 3; ++a) o[a] = 3 * coord(rng);
    }
    // Limits: none, an integer, or (for power-of-two steps) exactly the entry distance.
    long double limit = kInf<long double>;
    const int which = pick(rng);
    if (which < 3) limit = step(rng);
    bool touch = false;
    const bool exact = exact_meets(o, d, lo, hi, limit, touch);
    const Box<T> b = box<T>(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    const Ray<T> ray{{T(o[0]), T(o[1]), T(o[2])}, {T(d[0]), T(d[1]), T(d[2])}, kInf<T>};
    const T lim = static_cast<T>(limit);
    const bool computed = hit_box(box_ray(ray), b, lim);
    if (exact) {
      INFO("o " << o[0] << " " << o[1] << " " << o[2] << " d " << d[0] << " " << d[1] << " " << d[2] << " box "
                << lo[0] << " " << lo[1] << " " << lo[2] << " / " << hi[0] << " " << hi[1] << " " << hi[2]
                << " limit " << static_cast<double>(limit));
      REQUIRE(computed);
      ++meets;
      touching += touch;
    } else {
      misses += !computed;
    }
    // Ties with the limit: the limit exactly the exact entry distance (representable when d
    // along the entry axis is a power of two): the box must be kept.
    if (exact && which >= 8) {
      bool t2 = false;
      // Exact entry distance = max over axes of the near distances (and 0).
      long double entry = 0;
      for (int a = 0; a < 3; ++a)
        if (d[a]) entry = std::max(entry, static_cast<long double>(d[a] > 0 ? lo[a] - o[a] : hi[a] - o[a]) / d[a]);
      if (static_cast<long double>(static_cast<T>(entry)) == entry && exact_meets(o, d, lo, hi, entry, t2)) {
        CHECK(hit_box(box_ray(ray), b, static_cast<T>(entry)));
        ++ties;
      }
    }
  }
  INFO("meets " << meets << ", touching in one point " << touching << ", limit ties " << ties << ", misses " << misses);
  CHECK(meets > 20000);
  CHECK(touching > 1000);  // the hard cases really occur
  CHECK(ties > 1000);
  CHECK(misses > 20000);   // and the test does reject
}

TEST_CASE("bvh: round_out encloses the padded double box", "[bvh]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> v(-1000, 1000);
  for (int i = 0; i < 10000; ++i) {
    Box<double> b;
    b.extend(Vec3d(v(rng), v(rng), v(rng)));
    b.extend(Vec3d(v(rng), v(rng), v(rng)));
    const double pad = i % 2 ? 0 : 1e-3;
    const Box<float> f = round_out<float>(b, pad);
    for (int a = 0; a < 3; ++a) {
      REQUIRE(static_cast<double>(f.lo[a]) <= b.lo[a] - pad);
      REQUIRE(static_cast<double>(f.hi[a]) >= b.hi[a] + pad);
      // and by at most one float ulp beyond
      REQUIRE(std::nextafter(f.lo[a], kInf<float>) > b.lo[a] - pad);
    }
  }
}

TEST_CASE("bvh: the build partitions the triangles into contiguous leaves under boxes that hold them", "[bvh]") {
  std::mt19937_64 rng(11);
  for (int n : {1, 2, 3, 9, 100, 2000}) {
    INFO(n << " triangles");
    const auto tris = random_triangles(rng, n);
    const BvhBuild b = build_bvh(tris);
    check_tree(b, tris, BvhBuildParams{}.max_leaf);
    const BvhBuild again = build_bvh(tris);  // deterministic
    CHECK(again.order == b.order);
    CHECK(again.nodes.size() == b.nodes.size());
    if (n >= 100) CHECK(b.nodes.size() > static_cast<std::size_t>(n) / 8);  // the SAH does split
  }
}

TEST_CASE("bvh: coincident triangles are split by median and depth stays bounded", "[bvh]") {
  // 100 copies of one triangle: no split helps, but leaves are at most max_leaf.
  std::vector<Box<double>> same(100);
  for (auto& b : same) b = box<double>(0, 0, 0, 1, 1, 0);
  BvhBuild b = build_bvh(same);
  check_tree(b, same, 8);
  CHECK(b.depth <= 6);
  // A long chain of tiny triangles: SAH depth is capped, then medians.
  std::vector<Box<double>> chain;
  for (int i = 0; i < 5000; ++i) {
    const double x = std::ldexp(1.0, i % 60) * 1e-9;  // wildly varying scales
    chain.push_back(box<double>(x, 0, 0, x * 1.0001, 1e-12, 0));
  }
  b = build_bvh(chain);
  check_tree(b, chain, 8);
  CHECK(b.depth <= kBvhMaxDepth);
}

TEST_CASE("bvh: refit keeps the topology and encloses moved triangles", "[bvh]") {
  std::mt19937_64 rng(3);
  auto tris = random_triangles(rng, 500);
  BvhBuild b = build_bvh(tris);
  std::uniform_real_distribution<double> shift(-1, 1);
  std::vector<Box<double>> moved(tris.size());
  for (std::size_t k = 0; k < b.order.size(); ++k) {  // in leaf order, as refit_bvh wants them
    Box<double> t = tris[b.order[k]];
    const Vec3d s(shift(rng), shift(rng), shift(rng));
    t.lo += s;
    t.hi += s;
    moved[k] = t;
    tris[b.order[k]] = t;
  }
  const auto before = b.nodes;
  refit_bvh(b.nodes, moved);
  for (std::size_t i = 0; i < before.size(); ++i) {
    CHECK(b.nodes[i].offset == before[i].offset);
    CHECK(b.nodes[i].count == before[i].count);
  }
  check_tree(b, tris, 8);
}
