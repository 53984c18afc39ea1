// The intersection unit's kernels over a chunk of W consecutive entries of object memory
// (W = 8 floats or 4 doubles, geom/simd.h): Moller-Trumbore and the watertight test over the
// W triangles of a storage block (geom/triangle_soa.h), the sphere test over W of a unit's
// world spheres (geom/sphere_soa.h). One
// source per kernel for both precisions, over the pack type; the scalar kernels
// (geom/triangle.h, geom/watertight.h, geom/sphere.h) stay the definition and the fallback.
//
// Why they give the scalar kernels' bits, exactly.
//  - Same operations in the same order: each line below is the scalar kernel's line, lane
//    by lane, with the same operands in the same association ((a + b) + c stays so). Each
//    pack operation is one IEEE operation per lane with the scalar operation's rounding
//    (geom/simd.h); nothing is contracted into an FMA (-ffp-contract=off; no vfmadd in
//    these kernels' code, see docs/results.md "Kernels: SIMD").
//  - Lanes compute what the scalar kernel would not have computed (u after det == 0, the
//    triangles of a storage block outside the range [first, end) tested, v after every
//    lane has left at u): those values are never read, their lanes are masked. Each
//    stage's outcome is a bit mask of the lanes still in the test; a later stage only
//    narrows it, and a lane's exit stage is the number of stage masks it is in.
//    The masks and the comparisons are those of the scalar code, with NaN lanes compared
//    as C++ compares them (ordered predicates, unordered for !=).
//  - Divisions: t = tz / det is divided on every lane with the scalar operands (identical
//    per lane); u and v are divided in scalar code, only for the lanes that hit.
//  - Watertight's exact fallback (an edge function that rounds to 0 is recomputed exactly,
//    detail::edge) is taken per lane, by the scalar code, for the lanes that rounded to 0;
//    its value and sign replace that lane's.
//  - The caller (geom/triangle_soa.h) merges the lanes in memory order with the scalar
//    loop's rules (lowest index among equal t; a shadow ray stops at its first hit, and
//    the lanes after it are not counted).
#pragma once

#include "geom/simd.h"
#include "geom/watertight.h"

#if OPRT_HAVE_AVX2
namespace oprt::simd {

// What the stages of one chunk left: pass[s] holds the lanes still in the test after stage
// s (so a lane's exit stage is how many of pass[0..2] hold it); hit the accepted lanes.
// t, and the barycentrics un / den and vn / den, are meaningful on the hit lanes only.
template <typename T>
struct ChunkResult {
  unsigned pass[3] = {0, 0, 0};
  unsigned hit = 0;
  Pack<T> t, un, vn, den;
};

// A ray in the Moller kernel's form, one copy per lane.
template <typename T>
struct MollerRayPack {
  Pack<T> ox, oy, oz, dx, dy, dz, tmax;
  explicit MollerRayPack(const Ray<T>& r)
      : ox(Pack<T>::splat(r.o.x)), oy(Pack<T>::splat(r.o.y)), oz(Pack<T>::splat(r.o.z)),
        dx(Pack<T>::splat(r.d.x)), dy(Pack<T>::splat(r.d.y)), dz(Pack<T>::splat(r.d.z)),
        tmax(Pack<T>::splat(r.tmax)) {}
};

// Moller-Trumbore (geom/triangle.h, intersect_moller) on the W triangles of a storage block
// (geom/triangle_soa.h: W values of stream j at blk + j W; streams v0, e1, e2, n, each x, y,
// z), on the lanes of `lanes`.
template <typename T>
OPRT_SIMD_INLINE ChunkResult<T> moller_chunk(const T* blk, unsigned lanes, const MollerRayPack<T>& r) {
  using P = Pack<T>;
  auto s = [blk](int j) { return P::load(blk + j * P::W); };
  ChunkResult<T> out;
  const P nx = s(9), ny = s(10), nz = s(11);
  const P det = -((r.dx * nx + r.dy * ny) + r.dz * nz);
  out.pass[0] = bits(det != P::splat(0)) & lanes;
  if (!out.pass[0]) return out;
  const P tvx = r.ox - s(0), tvy = r.oy - s(1), tvz = r.oz - s(2);
  const P cx = tvy * r.dz - tvz * r.dy, cy = tvz * r.dx - tvx * r.dz, cz = tvx * r.dy - tvy * r.dx;
  const P sign = select(det < P::splat(0), P::splat(-1), P::splat(1));
  const P adet = det * sign;
  const P u = ((s(6) * cx + s(7) * cy) + s(8) * cz) * sign;
  out.pass[1] = out.pass[0] & ~bits((u < P::splat(0)) | (u > adet));
  // (No early exit here: when most tests leave at u, whether any lane of a chunk survives
  // is a coin toss that costs a mispredicted branch; computing v always is cheaper.)
  const P v = -((s(3) * cx + s(4) * cy) + s(5) * cz) * sign;
  out.pass[2] = out.pass[1] & ~bits((v < P::splat(0)) | (u + v > adet));
  if (!out.pass[2]) return out;
  out.t = ((tvx * nx + tvy * ny) + tvz * nz) / det;
  out.hit = out.pass[2] & bits((out.t > P::splat(0)) & (out.t < r.tmax));
  out.un = u;
  out.vn = v;
  out.den = adet;
  return out;
}

// A ray in the watertight kernel's form (watertight_ray: permuted, dz dominant), one copy
// per lane.
template <typename T>
struct WatertightRayPack {
  Pack<T> ox, oy, oz, dx, dy, dz, tmax;  // o in permuted order: o[kx], o[ky], o[kz]
  explicit WatertightRayPack(const WatertightRay<T>& r)
      : ox(Pack<T>::splat(r.o[r.kx])), oy(Pack<T>::splat(r.o[r.ky])), oz(Pack<T>::splat(r.o[r.kz])),
        dx(Pack<T>::splat(r.dx)), dy(Pack<T>::splat(r.dy)), dz(Pack<T>::splat(r.dz)),
        tmax(Pack<T>::splat(r.tmax)) {}
};

// An edge function p q - r s on the lanes, with its sign as two lane masks (positive,
// negative; neither: zero or NaN, as detail::sign_of). The lanes of `lanes` that round to 0
// take detail::edge's exact fallback, in scalar code.
template <typename T>
struct Edge {
  Pack<T> e;
  unsigned pos, neg;
};
template <typename T>
OPRT_SIMD_INLINE Edge<T> edge(Pack<T> p, Pack<T> q, Pack<T> r, Pack<T> s, unsigned lanes) {
  using P = Pack<T>;
  Edge<T> x{p * q - r * s, 0, 0};
  x.pos = bits(x.e > P::splat(0));
  x.neg = bits(x.e < P::splat(0));
  unsigned zero = bits(x.e == P::splat(0)) & lanes;
  if (zero) {
    const Lanes<T> lp(p), lq(q), lr(r), ls(s);
    Lanes<T> le(x.e);
    for (; zero; zero &= zero - 1) {
      const unsigned i = static_cast<unsigned>(__builtin_ctz(zero));
      const double exact = detail::exact_cross(lp[i], lq[i], lr[i], ls[i]);
      le.x[i] = static_cast<T>(exact);
      x.pos |= static_cast<unsigned>(exact > 0) << i;
      x.neg |= static_cast<unsigned>(exact < 0) << i;
    }
    x.e = P::load(le.x);
  }
  return x;
}

// detail::owns_edge for the edge p -> q on the lanes, for a triangle whose interior lies on
// the left (pos) or right (neg) of it. The scalar code negates ex, ey when the interior is
// on the right and tests ey > 0 || (ey == 0 && ex > 0); here that test becomes
// ey < 0 || (ey == 0 && ex < 0) on the unnegated values, the same outcome for every value:
// negation is exact, -y > 0 iff y < 0, -y == 0 iff y == 0 (both zeros), and a NaN fails
// every comparison either way.
template <typename T>
OPRT_SIMD_INLINE unsigned owns_edge(Pack<T> px, Pack<T> py, Pack<T> qx, Pack<T> qy, unsigned left, unsigned right) {
  using P = Pack<T>;
  const P ex = qx - px, ey = qy - py, zero = P::splat(0);
  const unsigned flat = bits(ey == zero);
  const unsigned up = bits(ey > zero) | (flat & bits(ex > zero));
  const unsigned down = bits(ey < zero) | (flat & bits(ex < zero));
  return (left & up) | (right & down);
}

// The watertight test (geom/watertight.h, intersect_watertight) on the W triangles of a
// storage block (streams v0, v1, v2, each x, y, z), on the lanes of `lanes`, for a ray whose
// dominant axis is KZ: the components are read in the permuted order kx, ky, kz.
template <typename T, int KZ>
OPRT_SIMD_INLINE ChunkResult<T> watertight_chunk(const T* blk, unsigned lanes, const WatertightRayPack<T>& r) {
  using P = Pack<T>;
  constexpr int kx = KZ == 2 ? 0 : KZ + 1, ky = kx == 2 ? 0 : kx + 1, kz = KZ;
  auto s = [blk](int vertex, int axis) { return P::load(blk + (3 * vertex + axis) * P::W); };
  ChunkResult<T> out;
  const unsigned valid = lanes;
  const P Bx = s(1, kx) - r.ox, Bz = s(1, kz) - r.oz, By = s(1, ky) - r.oy;
  const P Cx = s(2, kx) - r.ox, Cz = s(2, kz) - r.oz, Cy = s(2, ky) - r.oy;
  const P Ax = s(0, kx) - r.ox, Az = s(0, kz) - r.oz, Ay = s(0, ky) - r.oy;
  const P bx = r.dz * Bx - r.dx * Bz, by = r.dz * By - r.dy * Bz;
  const P cx = r.dz * Cx - r.dx * Cz, cy = r.dz * Cy - r.dy * Cz;
  const Edge<T> U = edge(bx, cy, by, cx, valid);  // edge v1 -> v2
  const P ax = r.dz * Ax - r.dx * Az, ay = r.dz * Ay - r.dy * Az;
  const Edge<T> V = edge(cx, ay, cy, ax, valid);  // edge v2 -> v0
  // su * sv < 0: strictly opposite signs.
  out.pass[0] = valid & ~((U.pos & V.neg) | (U.neg & V.pos));
  if (!out.pass[0]) return out;
  const Edge<T> W = edge(ax, by, ay, bx, out.pass[0]);  // edge v0 -> v1
  out.pass[1] = out.pass[0] & ~((U.pos & W.neg) | (U.neg & W.pos) | (V.pos & W.neg) | (V.neg & W.pos));
  if (!out.pass[1]) return out;
  // s = su != 0 ? su : sv != 0 ? sv : sw, as the masks of s > 0 and s < 0.
  const unsigned zu = ~(U.pos | U.neg), zv = ~(V.pos | V.neg), zw = ~(W.pos | W.neg);
  const unsigned left = U.pos | (zu & V.pos) | (zu & zv & W.pos);
  const unsigned right = U.neg | (zu & V.neg) | (zu & zv & W.neg);
  unsigned reject = ~(left | right);  // s == 0
  if ((zu | zv | zw) & out.pass[1] & (left | right)) {  // on an edge or a vertex: top-left rule
    reject |= zu & ~owns_edge(bx, by, cx, cy, left, right);
    reject |= zv & ~owns_edge(cx, cy, ax, ay, left, right);
    reject |= zw & ~owns_edge(ax, ay, bx, by, left, right);
  }
  const P det = (U.e + V.e) + W.e;
  reject |= bits(det == P::splat(0));
  out.pass[2] = out.pass[1] & ~reject;
  if (!out.pass[2]) return out;
  const P tz = (U.e * Az + V.e * Bz) + W.e * Cz;
  const P d = r.dz * det;
  out.t = tz / d;
  out.hit = out.pass[2] & bits((out.t > P::splat(0)) & (out.t < r.tmax));
  out.un = V.e;  // weight of v1
  out.vn = W.e;  // weight of v2
  out.den = det;
  return out;
}

// hit_sphere (geom/sphere.h) on spheres k .. k+n-1; s: the streams cx, cy, cz, r. Bit i of
// the result: sphere k + i is hit.
template <typename T>
OPRT_SIMD_INLINE unsigned sphere_chunk(const T* const* s, std::size_t k, unsigned n, const Ray<T>& ray) {
  using P = Pack<T>;
  const P dx = P::splat(ray.d.x), dy = P::splat(ray.d.y), dz = P::splat(ray.d.z);
  const P fx = P::splat(ray.o.x) - P::load(s[0] + k, n), fy = P::splat(ray.o.y) - P::load(s[1] + k, n),
          fz = P::splat(ray.o.z) - P::load(s[2] + k, n);
  const P b = (fx * dx + fy * dy) + fz * dz;
  const P lx = fx - b * dx, ly = fy - b * dy, lz = fz - b * dz;
  const P r = P::load(s[3] + k, n);
  const P r2 = r * r;
  const unsigned miss = bits((lx * lx + ly * ly) + lz * lz > r2);
  const unsigned enter = bits((b <= P::splat(0)) | ((fx * fx + fy * fy) + fz * fz <= r2));
  return enter & ~miss & lanes_below(n);
}

}  // namespace oprt::simd
#endif  // OPRT_HAVE_AVX2
