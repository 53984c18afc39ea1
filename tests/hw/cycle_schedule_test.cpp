#include "hw/arch.h"
#include "hw/cycle_costs.h"
#include "hw/cycle_schedule.h"

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
