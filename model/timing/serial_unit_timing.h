// The serial intersection unit's time on a ray (the paper's IU: one adder, one multiplier,
// one operation at a time). Plain C++, the one place this is decided: the SystemC unit
// (hw/serial_unit.cpp), `lt` and the analytic level all call serial_ray().
//
// A ray's work is the functional trace's record (functional_frame.h): the unit's tests
// before each sphere it entered (node tests of its tree, then sphere tests), then in that
// sphere the transform, box set-up and box tests (--accel bvh) and triangle tests, with
// the stall of on-chip memory already counted by the trace (memory_timing.h); then the
// tests after the last entered sphere. Phases follow each other; nothing overlaps.
//
// Through a cache (--sram, object_memory_model.h) the visit's timing depends on what the
// cache holds when the unit gets there, so it is not in the trace: the unit walks the visit
// again for its addresses (visit_stream.h) and consumes its bursts item by item: a test
// starts when the unit is free and the item is there; the difference is stall.
#pragma once

#include "ref/functional_frame.h"
#include "timing/object_memory_model.h"
#include "timing/unit_state.h"
#include "timing/visit_stream.h"

#include <stdexcept>

namespace oprt::timing {

// The unit's costs inside a visit through its memory. `lead`: from the sphere hit (the first
// burst's request) to the first test: the transform, and the box set-up with a BVH.
struct VisitCosts {
  Cycle lead = 0;
  const std::uint32_t* triangle = nullptr;  // per exit stage
  Cycle box = 0;                            // per node
};
inline VisitCosts visit_costs(const Arch& a, bool box_setup) {
  const KernelCosts& k = a.kernel_costs();
  return {Cycle{k.transform} + (box_setup ? Cycle{a.costs.box_setup} : 0), k.tri_stage, Cycle{a.costs.box}};
}

// A visit's bursts as the serial unit consumes them: one item after the other, each when the
// unit is free and the item is there. state(s, t) reports a change of the unit's state.
template <typename State>
class SerialVisit final : public BurstConsumer {
 public:
  SerialVisit(const VisitCosts& c, Cycle start, State& state) : c_(c), start_(start), t_(start + c.lead), work_(c.lead), state_(state) {}
  Cycle consume(const VisitStream& v, std::size_t b, std::size_t first, const Cycle* arrive) override {
    const std::uint32_t n = v.bursts[b].items;
    for (std::uint32_t j = 0; j < n; ++j) {
      const std::uint8_t stage = v.stages[first + j];
      const bool node = stage == kLogNode;
      if (arrive[j] > t_) {
        report(UnitState::stall, t_);
        t_ = arrive[j];
      }
      report(node ? UnitState::box : UnitState::primitive, t_);
      const Cycle cost = node ? c_.box : Cycle{c_.triangle[stage]};
      t_ += cost;
      work_ += cost;
    }
    return t_;
  }
  Cycle end() const { return t_; }
  Cycle stall() const { return t_ - start_ - work_; }

 private:
  void report(UnitState s, Cycle t) {
    if (s != last_) state_(s, t);
    last_ = s;
  }
  const VisitCosts& c_;
  const Cycle start_;
  Cycle t_, work_;
  State& state_;
  UnitState last_ = UnitState::idle;
};

// What one unit needs to time a visit through its cache: the geometry, its registers, the
// addresses, the memory (read(stream, request, consumer) -> the last burst's end: the SystemC
// unit sends a transaction, the analytic level calls the model) and scratch.
template <typename T>
struct CachedVisits {
  const SceneGeometry<T>& geometry;
  const IuRegisters<T>& registers;
  const GeometryAddresses<T>& addresses;
  const Arch& arch;
  VisitStream stream;
  std::uint64_t stall = 0;  // the cache's, summed over the visits timed
};

// The visit to entered sphere v of ray r, from its sphere hit at `start`, through the
// memory. Returns its end; state(s, t) reports the unit's changes of state (transform
// first, then box, primitive and stall as they come).
template <typename T, typename Read, typename State>
Cycle cached_visit(CachedVisits<T>& c, const RayRecord<T>& r, const VisitWork& v, Cycle start, Read&& read,
                   State&& state) {
  const WorkCounts again = visit_stream(c.geometry, c.registers, r.ray, r.kind, v.entry, c.addresses, c.stream);
  if (again.tri_tests() != v.tri_tests || again.box_tests != v.box_tests)
    throw std::logic_error("a visit walked again for its addresses differs from the functional trace");
  const VisitCosts costs = visit_costs(c.arch, again.box_setups != 0);
  state(UnitState::transform, start);
  if (again.box_setups) state(UnitState::box, start + Cycle{c.arch.kernel_costs().transform});  // the box set-up
  SerialVisit<State> unit(costs, start, state);
  const Cycle end = read(c.stream, start, unit);
  c.stall += static_cast<std::uint64_t>(unit.stall());
  return std::max(end, unit.end());
}

// Unit u's work on a ray (record w, or null: it entered none of its spheres) from `start`.
// phase(state, from, to) for each phase in time order; a visit through a cache is
// visit(v, t) -> its end, which reports its own phases. Returns when the ray is done.
template <typename T, typename Visit, typename Phase>
Cycle serial_ray(const FunctionalFrame<T>& f, std::uint32_t u, const UnitRayWork* w, Cycle start, Cycle transform,
                 bool cached, Visit&& visit, Phase&& phase) {
  Cycle t = start;
  auto run = [&](UnitState s, std::uint64_t cycles) {
    if (!cycles) return;
    phase(s, t, t + static_cast<Cycle>(cycles));
    t += static_cast<Cycle>(cycles);
  };
  if (!w) {
    if (f.unit_top[u]) run(UnitState::node, f.node_cost);
    else run(UnitState::sphere, std::uint64_t{f.unit_entries[u]} * f.sphere_cost);
    return t;
  }
  const std::uint32_t i = f.units[u].index(w);
  std::uint32_t spheres = 0, nodes = 0;
  for (const VisitWork& v : f.visits_of(u, i)) {
    run(UnitState::node, std::uint64_t{v.nodes_before} * f.node_cost);
    run(UnitState::sphere, std::uint64_t{v.spheres_before} * f.sphere_cost);
    nodes += v.nodes_before;
    spheres += v.spheres_before;
    if (cached) {
      t = visit(v, t);
      continue;
    }
    run(UnitState::transform, static_cast<std::uint64_t>(transform));
    run(UnitState::box, v.box);
    run(UnitState::primitive, v.primitive);
    run(UnitState::stall, v.stall);
  }
  run(UnitState::node, std::uint64_t{f.node_tests_of(u, i) - nodes} * f.node_cost);
  run(UnitState::sphere, std::uint64_t{f.sphere_tests_of(u, i) - spheres} * f.sphere_cost);
  return t;
}

}  // namespace oprt::timing
