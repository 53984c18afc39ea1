#include "hw/functional_frame.h"

#include "ref/parallel.h"
#include "ref/stop.h"

#include <oneapi/tbb/enumerable_thread_specific.h>

namespace oprt::hw {

namespace {

// A record as a chunk keeps it: which unit, and indices local to the chunk.
struct ChunkRecord {
  std::uint32_t unit;
  UnitRayWork work;  // work.ray: local to the chunk
};

// What one chunk of pixels produced, in ray order.
template <typename T>
struct Chunk {
  std::vector<RayRecord<T>> rays;
  std::vector<std::uint32_t> pixel_rays;  // per pixel: its number of rays
  std::vector<ChunkRecord> records;
  std::vector<VisitWork> visits;
  std::vector<HitRecord<T>> hits;
  std::vector<std::uint32_t> records_of;  // per unit: how many records, visits and hits
  std::vector<std::uint32_t> visits_of;
  std::vector<std::uint32_t> hits_of;
};

// Per thread: the work tables every chunk adds to (integer sums, the same in any order).
struct Totals {
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;
  std::vector<UnitCycles> units;
  std::vector<std::array<std::uint64_t, kRayKinds>> node_tests;  // per unit
};

template <typename T>
class Recorder {
 public:
  Recorder(Chunk<T>& c, Totals& t, const Arch& a, std::size_t units) : c_(c), t_(t), arch_(a) {
    c_.records_of.assign(units, 0);
    c_.visits_of.assign(units, 0);
    c_.hits_of.assign(units, 0);
  }

  void begin_ray(const Ray<T>& ray, RayKind kind, std::size_t pixel, std::uint32_t slot) {
    kind_ = static_cast<int>(kind);
    c_.rays.push_back({ray, kind, static_cast<std::uint32_t>(pixel), slot});
    if (kind == RayKind::primary) c_.pixel_rays.push_back(0);
    ++c_.pixel_rays.back();
  }
  void begin_unit(std::uint32_t) {
    cur_ = UnitRayWork{};
    cur_.ray = static_cast<std::uint32_t>(c_.rays.size() - 1);
    cur_.first_visit = static_cast<std::uint32_t>(c_.visits.size());
    spheres_before_ = nodes_before_ = 0;
  }
  void visit(const SphereVisit& v) {
    cur_.node_tests += v.nodes_before;
    nodes_before_ += v.nodes_before;
    if (v.sphere == kNone) return;  // node tests after the last sphere (top_traverse.h)
    t_.per_sphere[kind_][v.sphere] += v.work;
    ++cur_.sphere_tests;
    ++spheres_before_;
    if (!v.work.transforms) return;
    const UnitCycles vc = visit_cycles<T>(v, arch_);
    VisitWork w;
    w.entry = v.entry;
    w.sphere = v.sphere;
    w.spheres_before = spheres_before_;
    w.nodes_before = nodes_before_;
    spheres_before_ = nodes_before_ = 0;
    w.box = static_cast<std::uint32_t>(vc.box);
    w.primitive = static_cast<std::uint32_t>(vc.primitive);
    w.stall = static_cast<std::uint32_t>(vc.stall);
    w.tri_tests = static_cast<std::uint32_t>(v.work.tri_tests());
    w.box_tests = static_cast<std::uint32_t>(v.work.box_tests);
    c_.visits.push_back(w);
    ++cur_.visits;
    cur_.transform += static_cast<std::uint32_t>(vc.transform);
    cur_.box += w.box;
    cur_.primitive += w.primitive;
    cur_.stall += w.stall;
  }
  void end_unit(std::uint32_t u, const UnitAnswer<T>& a) {
    UnitCycles& total = t_.units[u];
    total.sphere += std::uint64_t{cur_.sphere_tests} * arch_.costs.sphere;
    total.node += std::uint64_t{cur_.node_tests} * arch_.costs.node;
    t_.node_tests[u][kind_] += cur_.node_tests;
    // Every sphere missed (flat: all tested; tree: only its root tested): no record
    // (FunctionalFrame::breakdown).
    if (!cur_.visits && (cur_.node_tests == 0 || (cur_.node_tests == 1 && cur_.sphere_tests == 0))) return;
    total.transform += cur_.transform;
    total.box += cur_.box;
    total.primitive += cur_.primitive;
    total.stall += cur_.stall;
    cur_.occluded = a.occluded;
    if (a.hit.valid()) {
      cur_.hit = static_cast<std::uint32_t>(c_.hits.size());
      c_.hits.push_back(a.hit);
      ++c_.hits_of[u];
    }
    c_.records.push_back({u, cur_});
    ++c_.records_of[u];
    c_.visits_of[u] += cur_.visits;
  }
  void end_ray() {}

 private:
  Chunk<T>& c_;
  Totals& t_;
  const Arch& arch_;
  int kind_ = 0;
  UnitRayWork cur_;
  std::uint32_t spheres_before_ = 0, nodes_before_ = 0;
};

}  // namespace

template <typename T>
void trace_functional(FunctionalFrame<T>& out, const SceneGeometry<T>& g, const std::vector<IuRegisters<T>>& units,
                      const CameraRays& camera, const Shader<T>& shader, const Arch& arch, int width, int height) {
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const std::size_t spheres = g.sphere_count();
  const std::size_t n_units = units.size();
  out.image = FrameImage(width, height);
  out.sphere_cost = arch.costs.sphere;
  out.node_cost = arch.costs.node;
  out.unit_entries.clear();
  out.unit_top.clear();
  for (const IuRegisters<T>& r : units) {
    out.unit_entries.push_back(static_cast<std::uint32_t>(r.size()));
    out.unit_top.push_back(r.top.empty() ? 0 : 1);
  }

  const FrameTraceInputs<T> in{g, units, camera, shader, arch.memory.model == MemoryModel::latency};
  std::vector<Chunk<T>> chunks(chunk_count(pixels, kPixelsPerChunk));
  struct Local {
    Totals totals;
    PixelScratch<T> scratch;
  };
  tbb::enumerable_thread_specific<Local> locals([&] {
    Local l;
    for (auto& k : l.totals.per_sphere) k.assign(spheres, WorkCounts{});
    l.totals.units.assign(n_units, UnitCycles{});
    l.totals.node_tests.assign(n_units, {});
    return l;
  });
  parallel_chunks(pixels, kPixelsPerChunk, [&](std::size_t c, std::size_t begin, std::size_t end) {
    throw_if_stopped();
    Local& l = locals.local();
    Recorder<T> rec(chunks[c], l.totals, arch, n_units);
    for (std::size_t p = begin; p < end; ++p)
      trace_pixel(in, static_cast<int>(p % width), static_cast<int>(p / width), out.image, rec, l.scratch);
  });

  for (auto& k : out.per_sphere) k.assign(spheres, WorkCounts{});
  out.unit_cycles.assign(n_units, UnitCycles{});
  out.unit_node_tests.assign(n_units, {});
  for (const Local& l : locals) {
    for (int k = 0; k < kRayKinds; ++k)
      for (std::size_t s = 0; s < spheres; ++s) out.per_sphere[k][s] += l.totals.per_sphere[k][s];
    for (std::size_t u = 0; u < n_units; ++u) {
      out.unit_cycles[u] += l.totals.units[u];
      for (int k = 0; k < kRayKinds; ++k) out.unit_node_tests[u][k] += l.totals.node_tests[u][k];
    }
  }

  // Assemble: rays in pixel order; each unit's records, visits and hits in ray order, with
  // the chunks' local indices turned into the frame's and the unit's.
  const std::size_t n_chunks = chunks.size();
  std::vector<std::size_t> ray_base(n_chunks + 1, 0), pixel_base(n_chunks + 1, 0);
  // [chunk][unit]: where the chunk's records, visits and hits start in the unit's arrays
  std::vector<std::uint32_t> rec_base(n_chunks * n_units), visit_base(n_chunks * n_units), hit_base(n_chunks * n_units);
  out.units.resize(n_units);
  for (std::size_t u = 0; u < n_units; ++u) {
    std::uint32_t r = 0, v = 0, h = 0;
    for (std::size_t c = 0; c < n_chunks; ++c) {
      rec_base[c * n_units + u] = r;
      visit_base[c * n_units + u] = v;
      hit_base[c * n_units + u] = h;
      r += chunks[c].records_of[u];
      v += chunks[c].visits_of[u];
      h += chunks[c].hits_of[u];
    }
    out.units[u].work.resize(r);
    out.units[u].visits.resize(v);
    out.units[u].hits.resize(h);
  }
  for (std::size_t c = 0; c < n_chunks; ++c) {
    ray_base[c + 1] = ray_base[c] + chunks[c].rays.size();
    pixel_base[c + 1] = pixel_base[c] + chunks[c].pixel_rays.size();
  }
  const std::size_t rays = ray_base[n_chunks];
  out.rays.resize(rays);
  out.pixel_rays.resize(pixels + 1);
  parallel_chunks(n_chunks, 1, [&](std::size_t c, std::size_t, std::size_t) {
    const Chunk<T>& k = chunks[c];
    std::copy(k.rays.begin(), k.rays.end(), out.rays.begin() + static_cast<std::ptrdiff_t>(ray_base[c]));
    auto r = static_cast<std::uint32_t>(ray_base[c]);
    for (std::size_t p = 0; p < k.pixel_rays.size(); ++p) {
      out.pixel_rays[pixel_base[c] + p] = r;
      r += k.pixel_rays[p];
    }
    std::vector<std::uint32_t> next_rec(rec_base.begin() + c * n_units, rec_base.begin() + (c + 1) * n_units);
    std::vector<std::uint32_t> next_visit(visit_base.begin() + c * n_units, visit_base.begin() + (c + 1) * n_units);
    std::vector<std::uint32_t> next_hit(hit_base.begin() + c * n_units, hit_base.begin() + (c + 1) * n_units);
    for (const ChunkRecord& cr : k.records) {
      UnitTrace<T>& ut = out.units[cr.unit];
      UnitRayWork w = cr.work;
      w.ray += static_cast<std::uint32_t>(ray_base[c]);
      std::copy(k.visits.begin() + w.first_visit, k.visits.begin() + w.first_visit + w.visits,
                ut.visits.begin() + next_visit[cr.unit]);
      w.first_visit = next_visit[cr.unit];
      next_visit[cr.unit] += w.visits;
      if (w.hit != kNone) {
        ut.hits[next_hit[cr.unit]] = k.hits[w.hit];
        w.hit = next_hit[cr.unit]++;
      }
      ut.work[next_rec[cr.unit]++] = w;
    }
  });
  out.pixel_rays[pixels] = static_cast<std::uint32_t>(rays);
  // Each unit's index: one bit per ray, and the records before each 64-ray word.
  parallel_chunks(n_units, 1, [&](std::size_t u, std::size_t, std::size_t) {
    UnitTrace<T>& ut = out.units[u];
    const std::size_t words = rays / 64 + 1;
    ut.has.assign(words, 0);
    ut.rank.assign(words, 0);
    for (const UnitRayWork& w : ut.work) ut.has[w.ray >> 6] |= std::uint64_t{1} << (w.ray & 63);
    std::uint32_t before = 0;
    for (std::size_t i = 0; i < words; ++i) {
      ut.rank[i] = before;
      before += static_cast<std::uint32_t>(__builtin_popcountll(ut.has[i]));
    }
  });
}

template struct FunctionalFrame<float>;
template struct FunctionalFrame<double>;
template void trace_functional(FunctionalFrame<float>&, const SceneGeometry<float>&,
                               const std::vector<IuRegisters<float>>&, const CameraRays&, const Shader<float>&,
                               const Arch&, int, int);
template void trace_functional(FunctionalFrame<double>&, const SceneGeometry<double>&,
                               const std::vector<IuRegisters<double>>&, const CameraRays&, const Shader<double>&,
                               const Arch&, int, int);

}  // namespace oprt::hw
