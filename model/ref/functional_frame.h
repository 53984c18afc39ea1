// A frame's functional work, computed before it is timed. Which spheres a ray enters, the
// work of each visit and each unit's answer do not depend on time (ref/frame_trace.h), so the
// whole frame is traced first, on every thread the pool allows; then the timed model (the
// SystemC modules, or the analytic recurrence) places that work in time. The transactions
// still carry the rays and the units' answers; the GPP merges the answers and checks them
// against this record. Plain C++, no SystemC.
//
// Storage is sparse and small, because it holds a whole frame: a unit whose ray enters none
// of its spheres, the common case, has no record (it tested every sphere in its registers,
// or with a tree over its spheres only the root, and answered "miss" / "not occluded"); a
// record is 16 bytes. The per-sphere detail of a record (which spheres, what each cost) is
// kept only when something needs it: the waveform, which shows each phase, and object
// memories that are caches, which time each visit (timing/visit_stream.h).
#pragma once

#include "arch/arch.h"
#include "ref/bytes.h"
#include "ref/frame_trace.h"
#include "ref/route.h"
#include "sample/pixel_sample.h"
#include "ref/work.h"

#include <array>
#include <cstdint>
#include <vector>

namespace oprt {

// One unit's work on one ray, when it entered at least one sphere.
struct UnitRayWork {
  std::uint32_t ray = 0;
  std::uint32_t cycles = 0;  // busy and memory stall
  std::uint32_t bytes = 0;   // read from object memory: the triangles and nodes it tested
  std::uint32_t answer = kNone;  // primary: index into UnitTrace::hits; shadow: kOccluded; else kNone
};
constexpr std::uint32_t kOccluded = kNone - 1;
constexpr std::uint32_t kWaveEnd = 0x8000'0000u;
constexpr std::uint32_t kWorkSlices = 16;  // FunctionalFrame::sphere_slices  // a routed ray's last unit of a wave (FunctionalFrame::route_units)

// A sphere a unit entered on a ray (detail).
struct VisitWork {
  std::uint32_t entry = 0;   // position in the unit's registers
  std::uint32_t spheres_before = 0, nodes_before = 0;  // tests since the previous entered sphere, this one's included
  std::uint32_t box = 0, primitive = 0, stall = 0;  // cycles (the transform is the kernel's cost)
  std::uint32_t tri_tests = 0, box_tests = 0;       // what it streamed from object memory
};

// One unit's records for a frame, in ray order. A unit reads only its own: they lie
// together in memory, and finding the record of ray r takes a bit and a popcount in a
// small index (one bit per ray, one count per 64 rays) instead of a search.
template <typename T>
struct UnitTrace {
  std::vector<UnitRayWork> work;
  std::vector<HitRecord<T>> hits;
  std::vector<std::uint64_t> has;   // bit r % 64 of word r / 64: ray r has a record
  std::vector<std::uint32_t> rank;  // per word: records of the rays before it

  const UnitRayWork* find(std::uint32_t r) const {
    const std::uint64_t m = has[r >> 6];
    const std::uint32_t bit = r & 63;
    if (!((m >> bit) & 1)) return nullptr;
    return &work[rank[r >> 6] + static_cast<std::uint32_t>(__builtin_popcountll(m & ((std::uint64_t{1} << bit) - 1)))];
  }
  std::uint32_t index(const UnitRayWork* w) const { return static_cast<std::uint32_t>(w - work.data()); }
};

template <typename T>
struct FunctionalFrame {
  FunctionalFrame() = default;
  FunctionalFrame(const FunctionalFrame&) = delete;  // the records point into visit_store
  FunctionalFrame& operator=(const FunctionalFrame&) = delete;
  FunctionalFrame(FunctionalFrame&&) = default;
  FunctionalFrame& operator=(FunctionalFrame&&) = default;

  // Rays in functional order: per pixel its primary ray, then its shadow rays in light order.
  // A ray's id everywhere in the timed model is its index here.
  std::vector<RayRecord<T>> rays;
  // Pixel p (the p-th traced: with --sample, the sample's p-th) owns rays [pixel_rays[p],
  // pixel_rays[p + 1]); RayRecord::pixel is that p, frame_pixel(p) the frame's pixel.
  std::vector<std::uint32_t> pixel_rays;
  const PixelSample* sample = nullptr;    // the pixels traced (sample/pixel_sample.h); null: every one
  std::uint32_t frame_pixel(std::uint32_t p) const { return sample ? sample->pixel(p) : p; }
  std::vector<UnitTrace<T>> units;
  bool detailed = false;                  // the records' detail was kept
  // The detail, per chunk of kPixelsPerChunk pixels, as the trace wrote it (never copied: a
  // frame's detail is held once): its visits, and per unit its records' entered spheres in
  // ray order (where they start, how many) and, with a tree, the entries and nodes tested.
  struct RecordDetail {
    std::uint32_t first_visit, visits;
  };
  struct ChunkDetail {
    std::vector<VisitWork> visits;
    std::vector<std::vector<RecordDetail>> records;                    // [unit]
    std::vector<std::vector<std::array<std::uint32_t, 2>>> tree_tests;  // [unit with a tree]: sphere, node tests
  };
  std::vector<ChunkDetail> detail;
  std::vector<std::uint32_t> record_base;  // [chunk * units + unit]: the unit's records in earlier chunks
  FrameImage image;                       // what the frame renders (the GPP's pixels must agree)
  std::array<std::vector<WorkCounts>, kRayKinds> per_sphere;  // [kind][sphere]
  std::vector<UnitCycles> unit_cycles;    // per unit, busy and memory stall (no bus time)
  std::vector<std::uint32_t> unit_entries;  // per unit: spheres in its registers this frame
  std::vector<char> unit_top;             // per unit: it walks a tree over its spheres (--top bvh)
  std::vector<std::array<std::uint64_t, kRayKinds>> unit_node_tests;  // per unit and ray kind
  // Per unit and ray kind: the work of its sphere visits (the per-sphere table's share of
  // it; a replicated sphere's work lies on several units).
  std::vector<std::array<WorkCounts, kRayKinds>> unit_work;
  // When the work lies in the frame: the pixels in kSlices equal runs, in the order the GPP
  // issues them; per sphere and slice its busy cycles (tests, transforms, boxes,
  // triangles), per unit and slice its node tests' cycles ([x * kSlices + slice]). The
  // feedback policy's replication balances when each unit's work arrives, not only how much.
  static constexpr std::uint32_t kSlices = kWorkSlices;
  std::vector<std::uint64_t> sphere_slices, unit_node_slices;
  // Routing (ref/route.h; broadcast: empty): ray r went to the units route_units[route_first[r]
  // .. route_first[r + 1]), in order, the last of each wave flagged with kWaveEnd; and how many
  // (ray, unit) pairs `ordered` spared, in all and per ray.
  bool routed = false;
  std::vector<std::uint32_t> route_first, route_units, route_skips;
  std::uint32_t route_bounds = 0;  // boxes the router tested each ray against
  std::uint64_t skipped = 0;
  std::uint32_t sphere_cost = 0;          // cycles per sphere test
  std::uint32_t node_cost = 0;            // cycles per node test (--top bvh)

  std::uint32_t ray_count() const { return static_cast<std::uint32_t>(rays.size()); }
  // The units ray r goes to (routed only), in order: unit = entry & ~kWaveEnd.
  std::pair<const std::uint32_t*, const std::uint32_t*> route_of(std::uint32_t r) const {
    return {route_units.data() + route_first[r], route_units.data() + route_first[r + 1]};
  }
  // How many units' bounds ray r entered: those it went to and those `ordered` skipped.
  std::uint32_t route_entered(std::uint32_t r) const { return route_first[r + 1] - route_first[r] + route_skips[r]; }
  // Unit u's record for ray r, or null if the ray entered none of its spheres.
  const UnitRayWork* find(std::uint32_t r, std::uint32_t u) const { return units[u].find(r); }
  // Cycles unit u spends on a ray (busy and memory stall), with its record or without.
  std::uint64_t cycles(const UnitRayWork* w, std::uint32_t u) const {
    if (w) return w->cycles;
    return unit_top[u] ? node_cost : std::uint64_t{unit_entries[u]} * sphere_cost;  // with a tree: the root, missed
  }
  // Detail of unit u's record i: the spheres it entered, in the order it entered them.
  struct Visits {
    const VisitWork *first, *last;
    const VisitWork* begin() const { return first; }
    const VisitWork* end() const { return last; }
    std::uint32_t size() const { return static_cast<std::uint32_t>(last - first); }
  };
  Visits visits_of(std::uint32_t u, std::uint32_t i) const {
    const auto [c, j] = detail_index(u, i);
    const RecordDetail& d = detail[c].records[u][j];
    const VisitWork* first = detail[c].visits.data() + d.first_visit;
    return {first, first + d.visits};
  }
  // ... the register entries it tested: every one, but a shadow ray stops at its occluder,
  // which is its last entered sphere (traverse.h); with a tree, as the trace recorded them.
  std::uint32_t sphere_tests_of(std::uint32_t u, std::uint32_t i) const {
    if (unit_top[u]) {
      const auto [c, j] = detail_index(u, i);
      return detail[c].tree_tests[u][j][0];
    }
    if (units[u].work[i].answer == kOccluded) return visits_of(u, i).last[-1].entry + 1;
    return unit_entries[u];
  }
  // ... and the nodes of its tree it tested.
  std::uint32_t node_tests_of(std::uint32_t u, std::uint32_t i) const {
    if (!unit_top[u]) return 0;
    const auto [c, j] = detail_index(u, i);
    return detail[c].tree_tests[u][j][1];
  }
  // Unit u's work on a ray with record w (or none): the spheres it entered and the register
  // entries it tested (without a record: every entry of a flat unit, none of a tree's).
  struct RayVisits {
    Visits visits;
    std::uint32_t sphere_tests;
  };
  RayVisits ray_visits(const UnitRayWork* w, std::uint32_t u) const {
    if (!w) return {{nullptr, nullptr}, unit_top[u] ? 0 : unit_entries[u]};
    const std::uint32_t i = units[u].index(w);
    return {visits_of(u, i), sphere_tests_of(u, i)};
  }
  // Unit u's record i is record j of the unit in chunk c.
  std::pair<std::size_t, std::size_t> detail_index(std::uint32_t u, std::uint32_t i) const {
    const std::size_t c = rays[units[u].work[i].ray].pixel / kPixelsPerChunk;
    return {c, i - record_base[c * units.size() + u]};
  }
  // Unit u's answer to ray r.
  UnitAnswer<T> answer(const UnitRayWork* w, std::uint32_t u) const {
    UnitAnswer<T> a;
    if (w && w->answer == kOccluded) a.occluded = true;
    else if (w && w->answer != kNone) a.hit = units[u].hits[w->answer];
    return a;
  }
};

// Trace every pixel of the frame (or those of `sample`, in its order; the others marked as
// not traced in the image) for the units' registers (units[u] is unit u's), keeping each
// record's detail if `detail`, each ray sent to the units `route` chooses (null: every unit).
// Reuses `out`'s storage from frame to frame. Throws InputError if one unit's work on one
// ray would exceed 2^32 cycles.
template <typename T>
void trace_functional(FunctionalFrame<T>& out, const SceneGeometry<T>& geometry,
                      const std::vector<IuRegisters<T>>& units, const CameraRays& camera, const Shader<T>& shader,
                      const Arch& arch, int width, int height, bool detail, const RouteTable<T>* route = nullptr,
                      const PixelSample* sample = nullptr);

// Calls phase(state, cycles) for each phase of unit u's work on a ray in time order, as the
// unit performs it: sphere tests (and node tests of its tree), and for each entered sphere
// its transform, box tests, triangle tests and memory stall. The tests before a sphere is
// entered form one phase of node tests, then one of sphere tests. State codes are
// UnitState's (timing/unit_state.h): sphere 1, transform 2, primitive 3, stall 4, box 5,
// node 6. Needs the detail (FunctionalFrame::detailed).
template <typename T, typename Phase>
void for_each_phase(const FunctionalFrame<T>& f, const UnitRayWork* w, std::uint32_t u, std::uint32_t transform_cost,
                    Phase&& phase) {
  auto emit = [&](std::uint8_t state, std::uint64_t cycles) {
    if (cycles) phase(state, cycles);
  };
  if (!w) {
    if (f.unit_top[u]) emit(6, f.node_cost);
    else emit(1, std::uint64_t{f.unit_entries[u]} * f.sphere_cost);
    return;
  }
  const UnitTrace<T>& ut = f.units[u];
  const std::uint32_t i = ut.index(w);
  std::uint32_t spheres = 0, nodes = 0;
  for (const VisitWork& v : f.visits_of(u, i)) {
    emit(6, std::uint64_t{v.nodes_before} * f.node_cost);
    emit(1, std::uint64_t{v.spheres_before} * f.sphere_cost);
    spheres += v.spheres_before;
    nodes += v.nodes_before;
    emit(2, transform_cost);
    emit(5, v.box);
    emit(3, v.primitive);
    emit(4, v.stall);
  }
  emit(6, std::uint64_t{f.node_tests_of(u, i) - nodes} * f.node_cost);
  emit(1, std::uint64_t{f.sphere_tests_of(u, i) - spheres} * f.sphere_cost);
}

extern template struct FunctionalFrame<float>;
extern template struct FunctionalFrame<double>;
extern template void trace_functional(FunctionalFrame<float>&, const SceneGeometry<float>&,
                                      const std::vector<IuRegisters<float>>&, const CameraRays&, const Shader<float>&,
                                      const Arch&, int, int, bool, const RouteTable<float>*, const PixelSample*);
extern template void trace_functional(FunctionalFrame<double>&, const SceneGeometry<double>&,
                                      const std::vector<IuRegisters<double>>&, const CameraRays&,
                                      const Shader<double>&, const Arch&, int, int, bool, const RouteTable<double>*,
                                      const PixelSample*);

}  // namespace oprt
