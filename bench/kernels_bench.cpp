// The intersection unit's kernels, one call at a time: ray-sphere (the stable form the
// model runs, and the paper's textbook form), the ray transform into a local frame, and
// the triangle test by the stage at which it exits. Each benchmark runs one kernel over a
// batch of different, seeded random inputs; items/s is kernel calls per second on one core.
//
// Triangle kernels are benchmarked through a small adapter (struct Moller below): to add a
// kernel, write its adapter (prepare a triangle, run the test, name its exit stage for each
// geometric case) and add one line to the registration list at the bottom.
//
// Blocks (block/...): the block functions as the units call them, one ray against a
// sphere's 2048 triangles in object memory, with the scalar kernels (OPRT_SIMD=off) and the
// SIMD ones (geom/simd_kernels.h) side by side, per kernel, precision and exit mix; items/s
// is triangle tests per second, and the counters give the mix (fraction of tests leaving at
// each stage).
#include "geom/affine.h"
#include "geom/simd.h"
#include "geom/sphere.h"
#include "geom/sphere_soa.h"
#include "geom/triangle.h"
#include "geom/triangle_soa.h"
#include "geom/watertight.h"

#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

namespace {

using namespace oprt;

constexpr std::size_t kBatch = 1024;

template <typename T>
Vec3<T> random_point(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return Vec3<T>(Vec3d(u(rng), u(rng), u(rng)));
}

template <typename T>
Vec3<T> unit(const Vec3<T>& v) {
  return v / std::sqrt(dot3(v, v));
}

// ---------------------------------------------------------------------------------- spheres
// Spheres of radius 1 around the origin's neighbourhood; rays from far away aimed at a point
// at distance `aim` from the centre: aim < 1 hits, aim > 1 misses (both forms agree there).
template <typename T>
struct SphereBatch {
  std::vector<Ray<T>> rays;
  std::vector<Sphere<T>> spheres;
  explicit SphereBatch(double aim) {
    std::mt19937 rng(7);
    for (std::size_t i = 0; i < kBatch; ++i) {
      const Vec3d c(random_point<double>(rng, -10, 10));
      const Vec3d o = c + 30.0 * Vec3d(unit(random_point<double>(rng, -1, 1)));
      Vec3d side = cross3(c - o, Vec3d(0, 1, 0.3));
      side = side / std::sqrt(dot3(side, side));
      const Vec3d target = c + aim * side;
      spheres.push_back({Vec3<T>(c), T(1)});
      rays.push_back({Vec3<T>(o), Vec3<T>(unit(target - o)), kInf<T>});
    }
  }
};

template <typename T, bool (*Test)(const Ray<T>&, const Sphere<T>&)>
void BM_sphere(benchmark::State& state) {
  const SphereBatch<T> b(state.range(0) ? 0.5 : 1.5);
  std::size_t hits = 0;
  for (auto _ : state)
    for (std::size_t i = 0; i < kBatch; ++i) {
      const bool h = Test(b.rays[i], b.spheres[i]);
      benchmark::DoNotOptimize(h);
      hits += h;
    }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
  state.counters["hit_fraction"] = static_cast<double>(hits) / (state.iterations() * kBatch);
}

// -------------------------------------------------------------------------------- transform
template <typename T>
void BM_transform(benchmark::State& state) {
  std::mt19937 rng(11);
  std::vector<Affine<T>> maps;
  std::vector<Ray<T>> rays;
  for (std::size_t i = 0; i < kBatch; ++i) {
    const Affine<double> m = translate(random_point<double>(rng, -5, 5)) *
                             rotate(random_point<double>(rng, -1, 1) + Vec3d(0, 0, 2), 0.7) * scale(Vec3d(1.5));
    maps.push_back(inverse(m)->template cast<T>());
    rays.push_back({random_point<T>(rng, -20, 20), unit(random_point<T>(rng, -1, 1)), kInf<T>});
  }
  for (auto _ : state)
    for (std::size_t i = 0; i < kBatch; ++i) {
      Ray<T> local = maps[i].ray(rays[i]);
      benchmark::DoNotOptimize(local);
    }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
}

// -------------------------------------------------------------------------------- triangles
// Geometric cases, each built so that every ray of the batch leaves the test the same way.
enum class Case { parallel, outside_first_edge, outside_second_edge, hit, behind };
const char* case_name(Case c) {
  switch (c) {
    case Case::parallel: return "parallel";
    case Case::outside_first_edge: return "outside_u";
    case Case::outside_second_edge: return "outside_v";
    case Case::hit: return "hit";
    case Case::behind: return "behind";
  }
  return "?";
}

// Triangles in planes z = z0 with random x, y vertices (so that a ray with d.z = 0 is
// exactly parallel); rays from off the plane towards the point with barycentrics (b1, b2),
// i.e. v0 + b1 e1 + b2 e2.
struct TriangleCase {
  Vec3d v0, v1, v2;
  Vec3d o, d;
};
std::vector<TriangleCase> triangle_cases(Case c) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<TriangleCase> out;
  while (out.size() < kBatch) {
    const double z = 5 * u(rng);
    const Vec3d v0(u(rng), u(rng), z), v1(u(rng), u(rng), z), v2(u(rng), u(rng), z);
    const Vec3d n = cross3(v1 - v0, v2 - v0);
    if (std::abs(n.z) < 0.1) continue;  // keep well-shaped triangles
    double b1 = 0.2, b2 = 0.3;
    if (c == Case::outside_first_edge) b1 = -0.5;
    if (c == Case::outside_second_edge) b2 = -0.5;
    const Vec3d target = v0 + b1 * (v1 - v0) + b2 * (v2 - v0);
    const Vec3d o = target + Vec3d(0.3 * u(rng), 0.3 * u(rng), 4 + u(rng));
    Vec3d d = target - o;
    if (c == Case::parallel) d.z = 0, d.x += 0.5;
    if (c == Case::behind) d = -d;
    out.push_back({v0, v1, v2, o, d / std::sqrt(dot3(d, d))});
  }
  return out;
}

// Kernel adapters. Stage names are the kernel's own; expect() is the stage every ray of a
// case must exit at (the benchmark fails rather than time the wrong path).
// RayIn is what the unit holds per ray once it is in the local frame (the per-ray set-up is
// part of the transform, so it is prepared outside the timed loop).
struct Moller {
  static constexpr const char* name = "moller";
  template <typename T>
  using Triangle = MollerTriangle<T>;
  template <typename T>
  using RayIn = Ray<T>;
  template <typename T>
  static Triangle<T> prepare(const TriangleCase& c) {
    return prepare_moller<T>(c.v0, c.v1, c.v2);
  }
  template <typename T>
  static RayIn<T> ray(const Ray<T>& r) {
    return r;
  }
  template <typename T>
  static int run(const RayIn<T>& r, const Triangle<T>& t) {
    return static_cast<int>(intersect_moller(r, t).stage);
  }
  static int expect(Case c) {
    switch (c) {
      case Case::parallel: return static_cast<int>(TriStage::det);
      case Case::outside_first_edge: return static_cast<int>(TriStage::u);
      case Case::outside_second_edge: return static_cast<int>(TriStage::v);
      case Case::hit:
      case Case::behind: return static_cast<int>(TriStage::t);
    }
    return -1;
  }
};

// The watertight kernel's edge functions U, V, W belong to the edges opposite v0, v1, v2:
// a point outside the first edge (its v1 barycentric negative) gives V the sign opposite to
// U ('uv'); outside the second (v2 negative) W disagrees ('w'). A ray parallel to the plane
// but off it is not a case of its own here: the shear sees the triangle as a segment beside
// the ray, so it exits at 'uv' or 'w' like any miss ('det' needs the ray in the plane or a
// degenerate triangle). expect() = -1: not benchmarked.
struct Watertight {
  static constexpr const char* name = "watertight";
  template <typename T>
  using Triangle = WatertightTriangle<T>;
  template <typename T>
  using RayIn = WatertightRay<T>;
  template <typename T>
  static Triangle<T> prepare(const TriangleCase& c) {
    return prepare_watertight<T>(c.v0, c.v1, c.v2);
  }
  template <typename T>
  static RayIn<T> ray(const Ray<T>& r) {
    return watertight_ray(r);
  }
  template <typename T>
  static int run(const RayIn<T>& r, const Triangle<T>& t) {
    return static_cast<int>(intersect_watertight(r, t).stage);
  }
  static int expect(Case c) {
    switch (c) {
      case Case::parallel: return -1;
      case Case::outside_first_edge: return static_cast<int>(WtStage::uv);
      case Case::outside_second_edge: return static_cast<int>(WtStage::w);
      case Case::hit:
      case Case::behind: return static_cast<int>(WtStage::t);
    }
    return -1;
  }
};

template <typename Kernel, typename T>
void BM_triangle(benchmark::State& state, Case c) {
  std::vector<typename Kernel::template Triangle<T>> tris;
  std::vector<typename Kernel::template RayIn<T>> rays;
  for (const TriangleCase& tc : triangle_cases(c)) {
    tris.push_back(Kernel::template prepare<T>(tc));
    rays.push_back(Kernel::template ray<T>({Vec3<T>(tc.o), Vec3<T>(tc.d), kInf<T>}));
  }
  for (std::size_t i = 0; i < kBatch; ++i)
    if (Kernel::run(rays[i], tris[i]) != Kernel::expect(c)) {
      state.SkipWithError(("ray " + std::to_string(i) + " exits at another stage than the case's").c_str());
      return;
    }
  for (auto _ : state)
    for (std::size_t i = 0; i < kBatch; ++i) {
      const int stage = Kernel::run(rays[i], tris[i]);
      benchmark::DoNotOptimize(stage);
    }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
}

template <typename Kernel>
void register_triangle_kernel() {
  for (Case c : {Case::parallel, Case::outside_first_edge, Case::outside_second_edge, Case::hit, Case::behind}) {
    if (Kernel::expect(c) < 0) continue;
    const std::string stem = std::string("triangle/") + Kernel::name + "/" + case_name(c);
    benchmark::RegisterBenchmark((stem + "/float").c_str(), BM_triangle<Kernel, float>, c);
    benchmark::RegisterBenchmark((stem + "/double").c_str(), BM_triangle<Kernel, double>, c);
  }
}


// ----------------------------------------------------------------------------------- blocks
// Exit mixes, each a sphere's worth of triangles and the rays that enter it:
//   cloud     the paper's flying triangles (scene 'polygons'): 2048 triangles of size 0.09
//             in a unit ball, rays from 15 away through the ball; almost every test leaves
//             at the first barycentric stage, a few hit
//   parallel  triangles in planes z = const, rays with d.z = 0: Moller leaves at 'det'
//   stack     2048 copies of one triangle at z = 1 .. 2048, rays along z through it: every
//             test reaches 't' and hits (the worst case for the SIMD loop's hit merging)
enum class Mix { cloud, parallel, stack };
const char* mix_name(Mix m) { return m == Mix::cloud ? "cloud" : m == Mix::parallel ? "parallel" : "stack"; }
constexpr std::uint32_t kBlock = 2048;
constexpr std::size_t kBlockRays = 64;

template <typename T>
struct Block {
  TriangleStore<T> tris;
  std::vector<Ray<T>> rays;
  Block(Kernel k, Mix mix) : tris(k) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(-1, 1);
    auto in_ball = [&](double r) {
      for (;;) {
        const Vec3d p(u(rng), u(rng), u(rng));
        if (dot3(p, p) <= 1) return p * r;
      }
    };
    for (std::uint32_t i = 0; i < kBlock; ++i) {
      if (mix == Mix::cloud) {
        const Vec3d c = in_ball(1);
        tris.push_back(c + in_ball(0.09), c + in_ball(0.09), c + in_ball(0.09));
      } else if (mix == Mix::parallel) {
        const double z = u(rng);
        tris.push_back(Vec3d(u(rng), u(rng), z), Vec3d(u(rng), u(rng), z), Vec3d(u(rng), u(rng), z));
      } else {
        const double z = 1 + i;
        tris.push_back(Vec3d(-1, -1, z), Vec3d(2, -1, z), Vec3d(-1, 2, z));
      }
    }
    for (std::size_t i = 0; i < kBlockRays; ++i) {
      Vec3d o, d;
      if (mix == Mix::cloud) {
        o = Vec3d(unit(random_point<double>(rng, -1, 1))) * 15.0;
        d = in_ball(1) - o;
      } else if (mix == Mix::parallel) {
        o = Vec3d(u(rng), u(rng), u(rng)) * 3.0;
        d = Vec3d(u(rng), u(rng), 0);
      } else {
        o = Vec3d(0.1 * u(rng), 0.1 * u(rng), 0);
        d = Vec3d(0, 0, 1);
      }
      rays.push_back({Vec3<T>(o), Vec3<T>(d / std::sqrt(dot3(d, d))), kInf<T>});
    }
  }
};

template <typename T>
void BM_block(benchmark::State& state, Kernel k, Mix mix, bool simd, bool any) {
  if (simd && !simd_available()) {
    state.SkipWithError("this build has no SIMD kernels (no AVX2)");
    return;
  }
  const Block<T> b(k, mix);
  set_simd_mode(simd ? SimdMode::on : SimdMode::off);
  std::uint64_t stages[kTriStages] = {}, hits = 0;
  for (auto _ : state)
    for (const Ray<T>& ray : b.rays) {
      if (any) {
        const bool h = any_in_block(b.tris, 0, kBlock, ray, stages, &hits);
        benchmark::DoNotOptimize(h);
      } else {
        const BlockHit<T> h = nearest_in_block(b.tris, 0, kBlock, ray, stages, &hits);
        benchmark::DoNotOptimize(h);
      }
    }
  std::uint64_t tests = 0;
  for (auto c : stages) tests += c;
  state.SetItemsProcessed(static_cast<std::int64_t>(tests));
  for (int s = 0; s < kTriStages; ++s)
    state.counters[stage_names(k)[s]] = tests ? static_cast<double>(stages[s]) / static_cast<double>(tests) : 0;
}

void register_blocks() {
  for (Kernel k : {Kernel::moller, Kernel::watertight})
    for (Mix mix : {Mix::cloud, Mix::parallel, Mix::stack})
      for (bool any : {false, true}) {
        if (any && mix != Mix::cloud) continue;  // a shadow ray stops at its first hit: only the cloud
        for (bool dbl : {false, true})
          for (bool simd : {false, true}) {
            const std::string name = std::string(any ? "block_any/" : "block/") + to_string(k) + "/" + mix_name(mix) +
                                     (dbl ? "/double/" : "/float/") + (simd ? "simd" : "scalar");
            if (dbl)
              benchmark::RegisterBenchmark(name.c_str(), BM_block<double>, k, mix, simd, any);
            else
              benchmark::RegisterBenchmark(name.c_str(), BM_block<float>, k, mix, simd, any);
          }
      }
}

// A unit's sphere registers: one ray against 32 world spheres (the paper scenes' count),
// scalar and SIMD; items/s is sphere tests per second.
template <typename T>
void BM_sphere_registers(benchmark::State& state, bool simd) {
  if (simd && !simd_available()) {
    state.SkipWithError("this build has no SIMD kernels (no AVX2)");
    return;
  }
  const SphereBatch<T> b(0.5);
  std::vector<Sphere<T>> spheres(b.spheres.begin(), b.spheres.begin() + 32);
  SphereSoA<T> soa;
  for (const auto& s : spheres) soa.push_back(s);
  set_simd_mode(simd ? SimdMode::on : SimdMode::off);
  for (auto _ : state)
    for (std::size_t r = 0; r < 64; ++r)
      for (std::size_t i = 0; i < spheres.size(); i += kLanes<T>) {
        const unsigned h = sphere_hits(spheres, soa, b.rays[r], i, kLanes<T>);
        benchmark::DoNotOptimize(h);
      }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * 64 * spheres.size()));
}

// Arg: 1 = the rays hit, 0 = they miss.
BENCHMARK_TEMPLATE(BM_sphere, float, hit_sphere<float>)->Name("sphere/stable/float")->Arg(1)->Arg(0);
BENCHMARK_TEMPLATE(BM_sphere, double, hit_sphere<double>)->Name("sphere/stable/double")->Arg(1)->Arg(0);
BENCHMARK_TEMPLATE(BM_sphere, float, hit_sphere_textbook<float>)->Name("sphere/textbook/float")->Arg(1)->Arg(0);
BENCHMARK_TEMPLATE(BM_sphere, double, hit_sphere_textbook<double>)->Name("sphere/textbook/double")->Arg(1)->Arg(0);
BENCHMARK_TEMPLATE(BM_transform, float)->Name("transform/float");
BENCHMARK_TEMPLATE(BM_transform, double)->Name("transform/double");

}  // namespace

int main(int argc, char** argv) {
  register_triangle_kernel<Moller>();  // add a kernel here, with its adapter above
  register_triangle_kernel<Watertight>();
  register_blocks();
  for (bool simd : {false, true}) {
    const std::string mode = simd ? "simd" : "scalar";
    benchmark::RegisterBenchmark(("sphere/registers/float/" + mode).c_str(), BM_sphere_registers<float>, simd);
    benchmark::RegisterBenchmark(("sphere/registers/double/" + mode).c_str(), BM_sphere_registers<double>, simd);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
