#include "arch/arch.h"
#include "arch/cycle_costs.h"
#include "arch/cycle_schedule.h"

#include <catch2/catch.hpp>

#include <map>

using namespace oprt;

namespace {
// Independent check of a schedule: every op placed once, after its inputs, at most one op
// per unit per cycle.
void check_valid(const Schedule& s) {
  const OpGraph& g = *s.graph;
  std::map<std::string, int> at;
  std::map<std::pair<int, int>, int> used;  // (cycle, unit) -> ops
  for (std::size_t i = 0; i < g.ops.size(); ++i) {
    REQUIRE(s.cycle[i] >= 1);
    at[g.ops[i].name] = s.cycle[i];
    ++used[{s.cycle[i], static_cast<int>(g.ops[i].fu)}];
  }
  for (std::size_t i = 0; i < g.ops.size(); ++i)
    for (const auto& in : g.ops[i].in) CHECK(at.at(in) < s.cycle[i]);
  for (const auto& [k, n] : used) CHECK(n == 1);
}
}  // namespace

TEST_CASE("schedules: the triangle test exits at 4 14 17 and 22 cycles", "[schedule]") {
  const Schedule s = list_schedule(moller_graph());
  check_valid(s);
  CHECK(s.exit_cycle == std::vector<int>{4, 14, 17, 22});  // the paper's range is 4 to 22
  // 21 multiplies and 18 adds in 22 cycles: the multiplier is busy in all but one cycle.
  int muls = 0, adds = 0;
  for (const Op& op : moller_graph().ops) (op.fu == Fu::multiplier ? muls : adds) += 1;
  CHECK(muls == 21);
  CHECK(adds == 18);
}

TEST_CASE("schedules: the watertight test exits at 18 20 21 and 27 cycles, its transform takes 20", "[schedule]") {
  const Schedule s = list_schedule(watertight_graph());
  check_valid(s);
  CHECK(s.exit_cycle == std::vector<int>{18, 20, 21, 27});
  // 25 multiplies and 24 adds: the first exit needs every vertex sheared (12 multiplies)
  // and two edge functions (4), so it cannot come before cycle 18 (one translation first,
  // 16 multiplies, the subtraction of V last).
  int muls = 0, adds = 0;
  for (const Op& op : watertight_graph().ops) (op.fu == Fu::multiplier ? muls : adds) += 1;
  CHECK(muls == 25);
  CHECK(adds == 24);
  const Schedule t = list_schedule(transform_watertight_graph());
  check_valid(t);
  CHECK(t.length() == 20);  // Moller's 19 and one comparison choosing the dominant axis
}

TEST_CASE("schedules: transform 19 and sphere tests 10 (textbook) and 14 (stable)", "[schedule]") {
  const Schedule t = list_schedule(transform_graph());
  check_valid(t);
  CHECK(t.length() == 19);  // Table 1
  const Schedule st = list_schedule(sphere_stable_graph());
  check_valid(st);
  CHECK(st.length() == 14);
  const Schedule tb = list_schedule(sphere_textbook_graph());
  check_valid(tb);
  CHECK(tb.length() == 10);
}

TEST_CASE("schedules: BVH box set-up 12 and box test 13", "[schedule][bvh]") {
  const Schedule setup = list_schedule(box_setup_graph());
  check_valid(setup);
  CHECK(setup.length() == 12);  // 12 multiplies (two Newton-Raphson steps per axis): multiplier-bound
  const Schedule box = list_schedule(box_graph());
  check_valid(box);
  CHECK(box.length() == 13);  // 12 adds (6 slab subtractions, 6 comparisons) + the slack multiply
  int muls = 0, adds = 0;
  for (const Op& op : box_graph().ops) (op.fu == Fu::multiplier ? muls : adds) += 1;
  CHECK(adds == 12);
  CHECK(muls == 7);
}

TEST_CASE("schedules: default costs are Table 1 and the schedules", "[schedule]") {
  const CycleCosts def, sched = scheduled_costs();
  CHECK(def.sphere == 9);
  CHECK(def.box_setup == sched.box_setup);
  CHECK(def.box == sched.box);
  for (Kernel kernel : {Kernel::moller, Kernel::watertight}) {
    INFO(to_string(kernel));
    CHECK(def.of(kernel).transform == sched.of(kernel).transform);
    for (int k = 0; k < kTriStages; ++k) CHECK(def.of(kernel).tri_stage[k] == sched.of(kernel).tri_stage[k]);
  }
  CHECK(sched.sphere == 14);
  CHECK(list_schedule(moller_graph()).table().find("det-u") != std::string::npos);
}

TEST_CASE("schedules: malformed graphs are refused", "[schedule]") {
  OpGraph bad{"bad", {"done"}, {{"a", Fu::adder, {"missing"}, 0}}};
  CHECK_THROWS_AS(list_schedule(bad), std::logic_error);
  OpGraph no_exit{"no exit", {"done"}, {{"a", Fu::adder, {}, -1}}};
  CHECK_THROWS_AS(list_schedule(no_exit), std::logic_error);
}

namespace {
// Independent check of a modulo schedule: every op after its inputs' results, and in every
// slot (cycle mod II) no more ops of a kind than the unit has of that kind.
void check_modulo(const Schedule& s, const FpUnits& u) {
  const OpGraph& g = *s.graph;
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < g.ops.size(); ++i) index[g.ops[i].name] = i;
  std::map<std::pair<int, int>, int> used;  // (slot, kind) -> ops
  for (std::size_t i = 0; i < g.ops.size(); ++i) {
    REQUIRE(s.cycle[i] >= 1);
    ++used[{s.cycle[i] % s.ii, static_cast<int>(g.ops[i].fu)}];
    for (const auto& in : g.ops[i].in) {
      const std::size_t j = index.at(in);
      const int lat = g.ops[j].fu == Fu::adder ? u.add_latency : u.multiply_latency;
      CHECK(s.cycle[j] + lat <= s.cycle[i]);
    }
  }
  for (const auto& [k, n] : used) CHECK(n <= (k.second == static_cast<int>(Fu::adder) ? u.adders : u.multipliers));
}
}  // namespace

TEST_CASE("modulo schedules: one instance per cycle with a unit per op, at the graph's critical path", "[schedule][pipelined]") {
  // Moller with 18 adders and 21 multipliers of latency 1: II 1, every op as soon as its
  // inputs are ready. det = (dx*nx + dy*ny) + dz*nz in cycle 3; u = e2.(tv x d): tvy,
  // tvy*dz, cx, e2x*cx, u', u, det-u: cycle 7; det-u-v waits for det-u: cycle 8, after which
  // the t stage (t' by cycle 4, its two comparisons by 6) is long done: latency 8.
  const FpUnits full = full_units(moller_graph());
  CHECK(full.adders == 18);
  CHECK(full.multipliers == 21);
  const Schedule s = modulo_schedule(moller_graph(), full);
  check_modulo(s, full);
  CHECK(s.ii == 1);
  CHECK(s.exit_cycle == std::vector<int>{3, 7, 8, 8});
  // The transform: a row is 3 multiplies then 2 (d') or 3 (o') adds: 1 + 2 + 1 = 4 cycles.
  const Schedule t = modulo_schedule(transform_graph(), full_units(transform_graph()));
  CHECK(t.ii == 1);
  CHECK(t.length() == 4);
}

TEST_CASE("modulo schedules: fewer units raise II to the resource bound; latencies stretch the chain", "[schedule][pipelined]") {
  // 18 adder ops on 6 adders and 21 multiplies on 7 multipliers: II = max(3, 3) = 3.
  const FpUnits third{6, 7, 1, 1};
  const Schedule s = modulo_schedule(moller_graph(), third);
  check_modulo(s, third);
  CHECK(s.ii == 3);
  // One adder and one multiplier: II = max(18, 21) = 21, the serial unit's throughput (its
  // list schedule takes 22 cycles per test: pipelining across tests saves the tail).
  const FpUnits one{1, 1, 1, 1};
  const Schedule o = modulo_schedule(moller_graph(), one);
  check_modulo(o, one);
  CHECK(o.ii == 21);
  // Multiplies of latency 3, adds of 2, a unit per op: the transform's row takes
  // 3 (multiply) + 2 + 2 (two adds) + 2 (the translation) = 9 cycles, from cycle 1: latency 9.
  const FpUnits slow = full_units(transform_graph(), 2, 3);
  const Schedule t = modulo_schedule(transform_graph(), slow);
  check_modulo(t, slow);
  CHECK(t.ii == 1);
  CHECK(t.length() == 9);
  CHECK_THROWS(modulo_schedule(moller_graph(), FpUnits{0, 1, 1, 1}));
}

TEST_CASE("modulo schedules: II rounds the ops per unit up and a stage exits when its result is out", "[schedule][pipelined]") {
  // 18 adder ops on 4 adders need 5 slots (4.5 rounded up), 21 multiplies on 4 multipliers 6:
  // II = 6. Rounding down would give 5, too few slots for 21 multiplies.
  const FpUnits four{4, 4, 1, 1};
  const Schedule s = modulo_schedule(moller_graph(), four);
  check_modulo(s, four);
  CHECK(s.ii == 6);
  // Multiplies of latency 3 and adds of 2, a unit per op: det = (dx*nx + dy*ny) + dz*nz has
  // its products issued in cycle 1 (out at the end of cycle 3), the first add in cycle 4 (out
  // at 5), the second in cycle 6, whose result is out at the end of cycle 7: the det stage
  // exits at 7, not at 6 when the op is issued.
  const FpUnits slow = full_units(moller_graph(), 2, 3);
  const Schedule t = modulo_schedule(moller_graph(), slow);
  check_modulo(t, slow);
  CHECK(t.ii == 1);
  CHECK(t.exit_cycle[0] == 7);
}
