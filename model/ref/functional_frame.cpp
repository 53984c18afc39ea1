#include "ref/functional_frame.h"

#include "ref/memory_timing.h"
#include "ref/parallel.h"
#include "ref/stop.h"
#include "base/error.h"

#include <stdexcept>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <string>

#include <oneapi/tbb/enumerable_thread_specific.h>

namespace oprt {

namespace {

// The cycles of one sphere visit. Memory stalls need the visit's exit stages in memory
// order (SphereVisit::stages), logged only when the memory is not ideal.
template <typename T>
inline UnitCycles visit_cycles(const SphereVisit& v, const Arch& a) {
  UnitCycles c;
  const KernelCosts& k = a.kernel_costs();
  c.sphere = v.work.sphere_tests * a.costs.sphere;
  c.transform = v.work.transforms * k.transform;
  c.primitive = primitive_cycles(v.work, k);
  c.box = box_cycles(v.work, a.costs);
  if (a.memory.model == MemoryModel::latency && v.work.transforms && v.stages) {
    StreamCosts s;
    s.latency = static_cast<std::uint32_t>(a.memory.latency_cycles);
    s.bytes_per_cycle = static_cast<std::uint32_t>(a.memory.bytes_per_cycle);
    s.triangle_bytes = Bytes<T>::triangle(a.kernel);
    s.node_bytes = Bytes<T>::node;
    s.lead = k.transform + (v.work.box_setups ? a.costs.box_setup : 0);
    s.triangle = k.tri_stage;
    s.box = a.costs.box;
    c.stall = stream_stall(s, v.stages, static_cast<std::uint32_t>(v.work.tri_tests() + v.work.box_tests));
  }
  return c;
}


// A record as a chunk keeps it: which unit, and indices local to the chunk.
struct ChunkRecord {
  std::uint32_t unit;
  UnitRayWork work;  // work.ray and work.answer: local to the chunk
};

// What one chunk of pixels produced, in ray order.
template <typename T>
struct Chunk {
  std::vector<RayRecord<T>> rays;
  std::vector<std::uint32_t> pixel_rays;  // per pixel: its number of rays
  std::vector<ChunkRecord> records;
  typename FunctionalFrame<T>::ChunkDetail* detail = nullptr;  // the frame's, for this chunk
  std::vector<HitRecord<T>> hits;
  std::vector<std::uint32_t> records_of;  // per unit: how many records, visits and hits
  std::vector<std::uint32_t> hits_of;
  // Routed (ref/route.h): per ray how many units it went to, and those units in order (the
  // last of each wave flagged).
  std::vector<std::uint32_t> route_count, route_units, route_skips;
  std::uint64_t skipped = 0;

  // Give back the growth slack while the chunk's thread goes on to its next chunk (it
  // reuses the memory): the frame's records are held at their size, not up to twice it.
  void shrink() {
    rays.shrink_to_fit();
    records.shrink_to_fit();
    route_count.shrink_to_fit();
    route_units.shrink_to_fit();
    hits.shrink_to_fit();
    if (!detail) return;
    detail->visits.shrink_to_fit();
    for (auto& r : detail->records) r.shrink_to_fit();
    for (auto& t : detail->tree_tests) t.shrink_to_fit();
  }
};

// Per thread: the work tables every chunk adds to (integer sums, the same in any order).
struct Totals {
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;
  std::vector<UnitCycles> units;
  std::vector<std::array<std::uint64_t, kRayKinds>> node_tests;  // per unit
  std::vector<std::array<WorkCounts, kRayKinds>> unit_work;      // per unit: its visits' work
  std::vector<std::uint64_t> sphere_slices, unit_node_slices;     // FunctionalFrame's, [x * kWorkSlices + slice]
};

template <typename T>
class Recorder {
 public:
  Recorder(Chunk<T>& c, Totals& t, const Arch& a, const std::vector<IuRegisters<T>>& regs, bool detail, bool routed,
           std::size_t pixels)
      : c_(c), t_(t), arch_(a), regs_(regs), detail_(detail), routed_(routed), node_bytes_(Bytes<T>::node),
        triangle_bytes_(Bytes<T>::triangle(a.kernel)), pixels_(pixels) {
    c_.records_of.assign(regs.size(), 0);
    c_.hits_of.assign(regs.size(), 0);
  }

  // The pixel traced next: its place in the frame's order of pixels (the sample's, with --sample).
  void at_pixel(std::size_t position) { pixel_ = position; }
  void begin_ray(const Ray<T>& ray, RayKind kind, std::size_t, int depth) {
    const std::size_t pixel = pixel_;
    kind_ = static_cast<int>(kind);
    slice_ = static_cast<std::uint32_t>(pixel * kWorkSlices / pixels_);
    RayRecord<T> r;
    r.ray = ray;
    r.kind = kind;
    r.depth = static_cast<std::uint8_t>(depth);
    r.pixel = static_cast<std::uint32_t>(pixel);
    c_.rays.push_back(r);
    if (kind == RayKind::primary) c_.pixel_rays.push_back(0);
    ++c_.pixel_rays.back();
    if (routed_) c_.route_count.push_back(0), c_.route_skips.push_back(0);
  }
  void begin_unit(std::uint32_t u) {
    if (routed_) {
      c_.route_units.push_back(u);
      ++c_.route_count.back();
    }
    unit_ = u;
    sphere_tests_ = visits_ = node_tests_ = 0;
    spheres_before_ = nodes_before_ = 0;
    bytes_ = 0;
    if (detail_) first_visit_ = static_cast<std::uint32_t>(c_.detail->visits.size());
    entered_ = UnitCycles{};
  }
  void visit(const SphereVisit& v) {
    node_tests_ += v.nodes_before;
    nodes_before_ += v.nodes_before;
    if (v.sphere == kNone) return;  // node tests after the last sphere (top_traverse.h)
    t_.per_sphere[kind_][v.sphere] += v.work;
    t_.unit_work[unit_][kind_] += v.work;
    std::uint64_t& in_slice = t_.sphere_slices[v.sphere * kWorkSlices + slice_];
    in_slice += arch_.costs.sphere;
    ++sphere_tests_;
    ++spheres_before_;
    if (!v.work.transforms) return;
    UnitCycles vc = visit_cycles<T>(v, arch_);
    vc.sphere = 0;  // counted for every visit in sphere_tests_
    in_slice += vc.busy();
    entered_ += vc;
    ++visits_;
    bytes_ += v.work.tri_tests() * triangle_bytes_ + v.work.box_tests * node_bytes_;
    if (!detail_) {
      spheres_before_ = nodes_before_ = 0;
      return;
    }
    VisitWork w;
    w.entry = v.entry;
    w.spheres_before = spheres_before_;
    w.nodes_before = nodes_before_;
    spheres_before_ = nodes_before_ = 0;
    w.box = static_cast<std::uint32_t>(vc.box);
    w.primitive = static_cast<std::uint32_t>(vc.primitive);
    w.stall = static_cast<std::uint32_t>(vc.stall);
    w.tri_tests = static_cast<std::uint32_t>(v.work.tri_tests());
    w.box_tests = static_cast<std::uint32_t>(v.work.box_tests);
    c_.detail->visits.push_back(w);
  }
  void end_unit(std::uint32_t u, const UnitAnswer<T>& a) {
    UnitCycles& total = t_.units[u];
    const std::uint64_t spheres = std::uint64_t{sphere_tests_} * arch_.costs.sphere;
    const std::uint64_t nodes = std::uint64_t{node_tests_} * arch_.costs.node;
    total.sphere += spheres;
    total.node += nodes;
    t_.node_tests[u][kind_] += node_tests_;
    t_.unit_node_slices[u * kWorkSlices + slice_] += nodes;
    // Every sphere missed (flat: all tested; with a tree: only its root tested, and missed):
    // no record (FunctionalFrame::cycles).
    if (!visits_ && (node_tests_ == 0 || (node_tests_ == 1 && sphere_tests_ == 0))) return;
    total += entered_;
    const std::uint64_t cycles = spheres + nodes + entered_.busy() + entered_.stall;
    if (cycles > kNone || bytes_ > kNone)
      throw InputError(arch_.source, "/costs",
                       "one unit's work on one ray would be " + std::to_string(cycles) + " cycles and " +
                           std::to_string(bytes_) + " bytes read, more than the 2^32 - 1 a ray's record holds: lower "
                           "the costs, split the objects into more spheres (--subdivide) or use --accel bvh");
    UnitRayWork w;
    w.ray = static_cast<std::uint32_t>(c_.rays.size() - 1);
    w.cycles = static_cast<std::uint32_t>(cycles);
    w.bytes = static_cast<std::uint32_t>(bytes_);
    if (a.occluded) {
      w.answer = kOccluded;
    } else if (a.hit.valid()) {
      w.answer = static_cast<std::uint32_t>(c_.hits.size());
      c_.hits.push_back(a.hit);
      ++c_.hits_of[u];
    }
    c_.records.push_back({u, w});
    ++c_.records_of[u];
    if (!detail_) return;
    c_.detail->records[u].push_back({first_visit_, visits_});
    if (!regs_[u].top.empty()) {
      c_.detail->tree_tests[u].push_back({sphere_tests_, node_tests_});
    } else if (node_tests_ != 0 ||  // flat: FunctionalFrame::sphere_tests_of derives them
               sphere_tests_ != (a.occluded ? c_.detail->visits.back().entry + 1 : regs_[u].size())) {
      throw std::logic_error("functional trace: a flat unit's sphere tests are not what its answer implies");
    }
  }
  void wave_end() {
    if (routed_ && c_.route_count.back()) c_.route_units.back() |= kWaveEnd;
  }
  void skip(std::uint32_t) {
    ++c_.skipped;
    ++c_.route_skips.back();
  }
  void end_ray(const RayEnd<T>& e) {
    RayRecord<T>& r = c_.rays.back();
    r.first_child = e.first_child;
    r.children = e.children;
    if (!e.hit.valid()) return;
    r.object = e.hit.object;
    r.prim = e.hit.prim;
    r.t = static_cast<float>(e.hit.t);
  }

 private:
  Chunk<T>& c_;
  Totals& t_;
  const Arch& arch_;
  const std::vector<IuRegisters<T>>& regs_;
  const bool detail_, routed_;
  const std::uint32_t node_bytes_, triangle_bytes_;
  const std::size_t pixels_;
  std::size_t pixel_ = 0;
  int kind_ = 0;
  std::uint32_t unit_ = 0, slice_ = 0;
  std::uint32_t sphere_tests_ = 0, visits_ = 0, first_visit_ = 0, node_tests_ = 0;
  std::uint32_t spheres_before_ = 0, nodes_before_ = 0;  // tests since the last entered sphere
  std::uint64_t bytes_ = 0;
  UnitCycles entered_;  // the visits that entered a sphere
};

// Per thread: its work tables, and the scratch space of its pixels.
template <typename T>
struct Local {
  Totals totals;
  PixelScratch<T> scratch;
};

// The frame's header: the units' register sizes and costs; the chunks' detail cleared.
template <typename T>
void prepare_frame(FunctionalFrame<T>& out, std::vector<Chunk<T>>& chunks, const std::vector<IuRegisters<T>>& units,
                   const Arch& arch, int width, int height, bool detail, const RouteTable<T>* route,
                   const PixelSample* sample) {
  out.image = FrameImage(width, height);
  out.sample = sample;
  if (sample) mark_not_traced(out.image, sample->pixels());
  out.detailed = detail;
  out.sphere_cost = arch.costs.sphere;
  out.node_cost = arch.costs.node;
  out.unit_entries.clear();
  out.unit_top.clear();
  for (const IuRegisters<T>& r : units) {
    out.unit_entries.push_back(static_cast<std::uint32_t>(r.size()));
    out.unit_top.push_back(r.top.empty() ? 0 : 1);
  }
  out.routed = route && route->routed();
  out.route_bounds = out.routed ? static_cast<std::uint32_t>(route->tested()) : 0;
  out.detail.resize(detail ? chunks.size() : 0);
  for (std::size_t c = 0; c < out.detail.size(); ++c) {
    auto& d = out.detail[c];
    d.visits.clear();
    d.records.resize(units.size());
    d.tree_tests.resize(units.size());
    for (auto& r : d.records) r.clear();
    for (auto& t : d.tree_tests) t.clear();
    chunks[c].detail = &d;
  }
}

// The threads' work tables, added up (integer sums: the same in any order).
template <typename T>
void sum_totals(FunctionalFrame<T>& out, const tbb::enumerable_thread_specific<Local<T>>& locals, std::size_t spheres,
                std::size_t n_units) {
  for (auto& k : out.per_sphere) k.assign(spheres, WorkCounts{});
  out.unit_cycles.assign(n_units, UnitCycles{});
  out.unit_node_tests.assign(n_units, {});
  out.unit_work.assign(n_units, {});
  out.sphere_slices.assign(spheres * kWorkSlices, 0);
  out.unit_node_slices.assign(n_units * kWorkSlices, 0);
  for (const Local<T>& l : locals) {
    for (std::size_t i = 0; i < out.sphere_slices.size(); ++i) out.sphere_slices[i] += l.totals.sphere_slices[i];
    for (std::size_t i = 0; i < out.unit_node_slices.size(); ++i) out.unit_node_slices[i] += l.totals.unit_node_slices[i];
    for (int k = 0; k < kRayKinds; ++k)
      for (std::size_t s = 0; s < spheres; ++s) out.per_sphere[k][s] += l.totals.per_sphere[k][s];
    for (std::size_t u = 0; u < n_units; ++u) {
      out.unit_cycles[u] += l.totals.units[u];
      for (int k = 0; k < kRayKinds; ++k) {
        out.unit_node_tests[u][k] += l.totals.node_tests[u][k];
        out.unit_work[u][k] += l.totals.unit_work[u][k];
      }
    }
  }
}

// Where each chunk's rays, pixels, routed units, and per unit records and hits start in the
// frame's arrays.
struct ChunkBases {
  std::vector<std::size_t> ray, pixel, route;  // [chunk], one more at the end
  std::vector<std::uint32_t> rec, hit;         // [chunk * units + unit]
};

template <typename T>
ChunkBases chunk_bases(FunctionalFrame<T>& out, const std::vector<Chunk<T>>& chunks, std::size_t n_units) {
  const std::size_t n_chunks = chunks.size();
  ChunkBases b{std::vector<std::size_t>(n_chunks + 1, 0), std::vector<std::size_t>(n_chunks + 1, 0),
               std::vector<std::size_t>(n_chunks + 1, 0), std::vector<std::uint32_t>(n_chunks * n_units),
               std::vector<std::uint32_t>(n_chunks * n_units)};
  out.units.resize(n_units);
  for (std::size_t u = 0; u < n_units; ++u) {
    std::uint32_t r = 0, h = 0;
    for (std::size_t c = 0; c < n_chunks; ++c) {
      b.rec[c * n_units + u] = r;
      b.hit[c * n_units + u] = h;
      r += chunks[c].records_of[u];
      h += chunks[c].hits_of[u];
    }
    out.units[u].work.resize(r);
    out.units[u].hits.resize(h);
  }
  for (std::size_t c = 0; c < n_chunks; ++c) {
    b.ray[c + 1] = b.ray[c] + chunks[c].rays.size();
    b.pixel[c + 1] = b.pixel[c] + chunks[c].pixel_rays.size();
    b.route[c + 1] = b.route[c] + chunks[c].route_units.size();
  }
  return b;
}

// Chunk c's rays, routes, pixels and records into the frame's arrays, its local indices
// turned into the frame's and the unit's; its memory is given back.
template <typename T>
void copy_chunk(FunctionalFrame<T>& out, Chunk<T>& k, std::size_t c, const ChunkBases& b, std::size_t n_units) {
  // The detail stays where the chunk wrote it (FunctionalFrame::visits_of): no copy.
  std::copy(k.rays.begin(), k.rays.end(), out.rays.begin() + static_cast<std::ptrdiff_t>(b.ray[c]));
  if (out.routed) {
    std::copy(k.route_units.begin(), k.route_units.end(), out.route_units.begin() + static_cast<std::ptrdiff_t>(b.route[c]));
    auto first = static_cast<std::uint32_t>(b.route[c]);
    for (std::size_t i = 0; i < k.route_count.size(); ++i) {
      out.route_first[b.ray[c] + i] = first;
      first += k.route_count[i];
    }
    std::copy(k.route_skips.begin(), k.route_skips.end(), out.route_skips.begin() + static_cast<std::ptrdiff_t>(b.ray[c]));
  }
  auto r = static_cast<std::uint32_t>(b.ray[c]);
  for (std::size_t p = 0; p < k.pixel_rays.size(); ++p) {
    out.pixel_rays[b.pixel[c] + p] = r;
    r += k.pixel_rays[p];
  }
  std::vector<std::uint32_t> next_rec(b.rec.begin() + c * n_units, b.rec.begin() + (c + 1) * n_units);
  std::vector<std::uint32_t> next_hit(b.hit.begin() + c * n_units, b.hit.begin() + (c + 1) * n_units);
  for (const ChunkRecord& cr : k.records) {
    UnitTrace<T>& ut = out.units[cr.unit];
    UnitRayWork w = cr.work;
    w.ray += static_cast<std::uint32_t>(b.ray[c]);
    if (w.answer != kNone && w.answer != kOccluded) {
      ut.hits[next_hit[cr.unit]] = k.hits[w.answer];
      w.answer = next_hit[cr.unit]++;
    }
    ut.work[next_rec[cr.unit]++] = w;
  }
  k = Chunk<T>{};  // its memory back before the next chunk's copy: peak = the frame, not twice it
}

// Assemble: rays in pixel order; each unit's records, visits and hits in ray order.
template <typename T>
void assemble(FunctionalFrame<T>& out, std::vector<Chunk<T>>& chunks, std::size_t pixels, std::size_t n_units) {
  const std::size_t n_chunks = chunks.size();
  const ChunkBases b = chunk_bases(out, chunks, n_units);
  out.skipped = 0;
  for (const Chunk<T>& k : chunks) out.skipped += k.skipped;
  out.record_base = b.rec;
  const std::size_t rays = b.ray[n_chunks];
  out.rays.resize(rays);
  out.pixel_rays.resize(pixels + 1);
  out.route_first.assign(out.routed ? rays + 1 : 0, 0);
  out.route_units.resize(out.routed ? b.route[n_chunks] : 0);
  out.route_skips.assign(out.routed ? rays : 0, 0);
  parallel_chunks(n_chunks, 1, [&](std::size_t c, std::size_t, std::size_t) { copy_chunk(out, chunks[c], c, b, n_units); });
  out.pixel_rays[pixels] = static_cast<std::uint32_t>(rays);
  if (out.routed) out.route_first[rays] = static_cast<std::uint32_t>(b.route[n_chunks]);
}

// Each unit's index: one bit per ray, and the records before each 64-ray word.
template <typename T>
void index_units(FunctionalFrame<T>& out) {
  const std::size_t rays = out.rays.size();
  parallel_chunks(out.units.size(), 1, [&](std::size_t u, std::size_t, std::size_t) {
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

}  // namespace

template <typename T>
void trace_functional(FunctionalFrame<T>& out, const SceneGeometry<T>& g, const std::vector<IuRegisters<T>>& units,
                      const CameraRays& camera, const Shader<T>& shader, const Arch& arch, int width, int height,
                      bool detail, const RouteTable<T>* route, const PixelSample* sample) {
  const std::size_t pixels = sample ? sample->size() : static_cast<std::size_t>(width) * height;
  const std::size_t spheres = g.sphere_count();
  const std::size_t n_units = units.size();
  std::vector<Chunk<T>> chunks(chunk_count(pixels, kPixelsPerChunk));
  prepare_frame(out, chunks, units, arch, width, height, detail, route, sample);
  const FrameTraceInputs<T> in{g, units, camera, shader, arch.memory.model == MemoryModel::latency, route};
  tbb::enumerable_thread_specific<Local<T>> locals([&] {
    Local<T> l;
    for (auto& k : l.totals.per_sphere) k.assign(spheres, WorkCounts{});
    l.totals.units.assign(n_units, UnitCycles{});
    l.totals.node_tests.assign(n_units, {});
    l.totals.unit_work.assign(n_units, {});
    l.totals.sphere_slices.assign(spheres * kWorkSlices, 0);
    l.totals.unit_node_slices.assign(n_units * kWorkSlices, 0);
    return l;
  });
  parallel_chunks(pixels, kPixelsPerChunk, [&](std::size_t c, std::size_t begin, std::size_t end) {
    throw_if_stopped();
    Local<T>& l = locals.local();
    Recorder<T> rec(chunks[c], l.totals, arch, units, detail, out.routed, pixels);
    for (std::size_t p = begin; p < end; ++p) {
      const std::size_t q = sample ? sample->pixel(p) : p;  // the frame's pixel
      rec.at_pixel(p);
      trace_pixel(in, static_cast<int>(q % width), static_cast<int>(q / width), out.image, rec, l.scratch);
    }
    chunks[c].shrink();
  });
  sum_totals(out, locals, spheres, n_units);
  assemble(out, chunks, pixels, n_units);
  index_units(out);
#ifdef __GLIBC__
  // The chunks' working storage, freed above by the pool's threads, stays in their malloc
  // arenas, counted in the process's memory for the rest of the frame: hand it back. (Once
  // per frame; on the room's 256x256 frame with --vcd it is 40 MB of peak resident memory.)
  malloc_trim(0);
#endif
}

template struct FunctionalFrame<float>;
template struct FunctionalFrame<double>;
template void trace_functional(FunctionalFrame<float>&, const SceneGeometry<float>&,
                               const std::vector<IuRegisters<float>>&, const CameraRays&, const Shader<float>&,
                               const Arch&, int, int, bool, const RouteTable<float>*, const PixelSample*);
template void trace_functional(FunctionalFrame<double>&, const SceneGeometry<double>&,
                               const std::vector<IuRegisters<double>>&, const CameraRays&, const Shader<double>&,
                               const Arch&, int, int, bool, const RouteTable<double>*, const PixelSample*);

}  // namespace oprt
