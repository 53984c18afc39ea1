// Ray-triangle intersection, watertight (Woop, Benthin, Wald, "Watertight Ray/Triangle
// Intersection", JCGT 2(1), 2013), in the form the intersection unit runs it: no divider,
// so the shear is multiplied through by the ray's dominant direction component.
//
// Why it is watertight. Every vertex is carried into a frame where the ray is the z axis
// by a map that depends only on that vertex and the ray: translate by -o, permute so that z
// is the dominant axis of d, and shear x' = dz x - dx z, y' = dz y - dy z. Two triangles
// sharing an edge therefore see the same two projected endpoints, bit for bit, and the edge
// function of that edge, a'x b'y - a'y b'x, is the same two products in both, so they compute
// it as exact negatives of each other. A positive or negative rounded value has the sign of
// the exact one (rounding is monotonic; the two products are rounded alike); only a rounded
// zero is ambiguous, and there the edge function is recomputed exactly (in double for float:
// the products of two floats are exact in double and one rounding keeps the sign; for
// double, an error-free expansion). So every edge function has its exact sign for the
// projected vertices, and the projected triangles partition the plane of the ray's origin
// without gaps: a ray inside the silhouette of a closed mesh hits it.
//
// Points exactly on an edge or a vertex. With exact signs these are the only ways to hit two
// triangles where one is meant. The tie is broken by a perturbation of the point that no
// edge can contain, (-1, +delta) for an infinitesimal delta: an edge function that is exactly
// zero counts as inside iff the edge, oriented with the triangle's interior on its left,
// points up, or exactly right (a top-left rule, as rasterisers use). Of two triangles that
// share an edge from opposite sides exactly one owns it, and of the triangles around a
// vertex exactly one owns the vertex. Two triangles that meet the ray at the same point from
// the same side (a silhouette fold) both keep it: that is two crossings, not a double hit.
//
// Numerics of t. t = T / D with T = U Az + V Bz + W Cz and D = dz (U + V + W): the computed
// t has a relative error of a few ulps of the largest |z| of the translated vertices plus
// terms that grow as D shrinks against the edge functions (a sliver, or a ray grazing the
// plane). Self-intersection of shadow rays is avoided by their origin's offset
// (ref/shading.cpp), which for this kernel includes the sliver term.
#pragma once

#include "geom/triangle.h"

#include <cmath>

namespace oprt {

// Object memory per triangle: the three vertices as prepared in double and rounded to T
// (36 bytes in float, 72 in double). A zero-area triangle is stored as three copies of
// its first vertex: then every edge function is exactly zero and the test exits at 'det'.
template <typename T>
struct WatertightTriangle {
  Vec3<T> v0, v1, v2;
};

template <typename T>
WatertightTriangle<T> prepare_watertight(const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
  const Vec3d n = cross3(v1 - v0, v2 - v0);
  const Vec3<T> a(v0);
  if (dot3(n, n) == 0) return {a, a, a};
  return {a, Vec3<T>(v1), Vec3<T>(v2)};
}

// Exit stages, in schedule order (arch/cycle_schedule.cpp, watertight_graph). As for Moller,
// a test that reaches 't' costs the same whether it accepts or rejects.
enum class WtStage : std::uint8_t {
  uv = 0,   // edge functions U and V of strictly opposite signs
  w = 1,    // W of the opposite sign to U or V
  det = 2,  // all three zero (degenerate triangle, or ray in its plane), or the point lies
            // exactly on an edge or vertex this triangle does not own
  t = 3,    // distance computed: accepted, or rejected outside (0, tmax)
};

// What the unit derives once per ray carried into a local frame: the dominant axis kz
// (ties go to the lower axis) and the other two in cyclic order.
template <typename T>
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;
  Vec3<T> o;
  T dx = 0, dy = 0, dz = 0;  // d permuted: dz the dominant component
  T tmax = kInf<T>;
};

template <typename T>
inline WatertightRay<T> watertight_ray(const Ray<T>& r) {
  const T ax = std::fabs(r.d.x), ay = std::fabs(r.d.y), az = std::fabs(r.d.z);
  WatertightRay<T> w;
  w.kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
  w.kx = w.kz == 2 ? 0 : w.kz + 1;
  w.ky = w.kx == 2 ? 0 : w.kx + 1;
  w.o = r.o;
  w.dx = r.d[w.kx];
  w.dy = r.d[w.ky];
  w.dz = r.d[w.kz];
  w.tmax = r.tmax;
  return w;
}

namespace detail {

// a b - c d with its exact sign (zero only if the exact value is zero), for the edge
// functions that round to zero. float: the products are exact in double, and the one
// rounding of their difference keeps the sign.
inline double exact_cross(float a, float b, float c, float d) {
  return static_cast<double>(a) * static_cast<double>(b) - static_cast<double>(c) * static_cast<double>(d);
}

inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a, av = s - bv;
  e = (a - av) + (b - bv);
}

// double: a b = p + e and c d = q + f exactly (fma gives the product's rounding error), and
// p - q + e - f is summed as a non-overlapping expansion (Shewchuk's Grow-Expansion), whose
// largest component carries the exact sign; the components summed from the smallest give a
// value with that sign. (Exact unless a product underflows.)
inline double exact_cross(double a, double b, double c, double d) {
  const double p = a * b, e = std::fma(a, b, -p);
  const double q = c * d, f = std::fma(c, d, -q);
  const double terms[4] = {p, -q, e, -f};
  double h[4];
  int n = 1;
  h[0] = terms[0];
  for (int k = 1; k < 4; ++k) {
    double q2 = terms[k];
    for (int i = 0; i < n; ++i) two_sum(q2, h[i], q2, h[i]);
    h[n++] = q2;
  }
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += h[i];
  for (int i = n - 1; i >= 0; --i)
    if (h[i] != 0) return h[i] > 0 ? std::fabs(sum) : -std::fabs(sum);
  return 0;
}

template <typename T>
inline int sign_of(T x) {
  return (x > 0) - (x < 0);
}

// An edge function of the form a b - c d, with its exact sign in *s.
template <typename T>
inline T edge(T a, T b, T c, T d, int* s) {
  T e = a * b - c * d;
  if (e == 0) {
    const double x = exact_cross(a, b, c, d);
    *s = sign_of(x);
    e = static_cast<T>(x);
  } else {
    *s = sign_of(e);
  }
  return e;
}

// Does a triangle whose interior lies on side `s` (+1 left, -1 right) of the edge from p to
// q own the points exactly on that edge? Top-left rule: oriented with the interior on its
// left, the edge must point up (+y) or exactly right (+x). The signs of the differences are
// exact, so two triangles on opposite sides of an edge always decide oppositely.
template <typename T>
inline bool owns_edge(T px, T py, T qx, T qy, int s) {
  T ex = qx - px, ey = qy - py;
  if (s < 0) {
    ex = -ex;
    ey = -ey;
  }
  return ey > 0 || (ey == 0 && ex > 0);
}

}  // namespace detail

// Vertices are read in permuted order (register routing, free in the unit). The operation
// order is the schedule's; with -ffp-contract=off every product and sum rounds as written.
template <typename T>
inline TriangleHit<T, WtStage> intersect_watertight(const WatertightRay<T>& r, const WatertightTriangle<T>& tri) {
  TriangleHit<T, WtStage> h;
  h.stage = WtStage::uv;
  const int kx = r.kx, ky = r.ky, kz = r.kz;
  const T Bx = tri.v1[kx] - r.o[kx], Bz = tri.v1[kz] - r.o[kz], By = tri.v1[ky] - r.o[ky];
  const T Cx = tri.v2[kx] - r.o[kx], Cz = tri.v2[kz] - r.o[kz], Cy = tri.v2[ky] - r.o[ky];
  const T Ax = tri.v0[kx] - r.o[kx], Az = tri.v0[kz] - r.o[kz], Ay = tri.v0[ky] - r.o[ky];
  const T bx = r.dz * Bx - r.dx * Bz, by = r.dz * By - r.dy * Bz;
  const T cx = r.dz * Cx - r.dx * Cz, cy = r.dz * Cy - r.dy * Cz;
  int su, sv, sw;
  const T U = detail::edge(bx, cy, by, cx, &su);  // edge v1 -> v2
  const T ax = r.dz * Ax - r.dx * Az, ay = r.dz * Ay - r.dy * Az;
  const T V = detail::edge(cx, ay, cy, ax, &sv);  // edge v2 -> v0
  if (su * sv < 0) return h;
  h.stage = WtStage::w;
  const T W = detail::edge(ax, by, ay, bx, &sw);  // edge v0 -> v1
  if (su * sw < 0 || sv * sw < 0) return h;
  h.stage = WtStage::det;
  const int s = su != 0 ? su : sv != 0 ? sv : sw;  // the side the interior is on
  if (s == 0) return h;
  if ((su == 0 && !detail::owns_edge(bx, by, cx, cy, s)) || (sv == 0 && !detail::owns_edge(cx, cy, ax, ay, s)) ||
      (sw == 0 && !detail::owns_edge(ax, ay, bx, by, s)))
    return h;
  const T det = (U + V) + W;
  if (det == 0) return h;  // only if the values underflowed while the signs did not
  h.stage = WtStage::t;
  const T tz = (U * Az + V * Bz) + W * Cz;
  const T d = r.dz * det;
  const T t = tz / d;
  if (!(t > 0 && t < r.tmax)) return h;
  h.hit = true;
  h.t = t;
  h.u = V / det;  // weight of v1
  h.v = W / det;  // weight of v2
  return h;
}

}  // namespace oprt
