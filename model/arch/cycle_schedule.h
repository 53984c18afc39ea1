// The intersection unit's arithmetic: one adder/subtractor and one multiplier, each taking
// one cycle per operation (the paper's assumption). Every IU operation is written here as
// the graph of its additions and multiplications, and a list scheduler places them on the
// two units cycle by cycle. The cycle counts the architecture charges by default come from
// these schedules (cycle_costs.h); `oprt_schedules` prints them as tables.
//
// Conventions. A comparison is a subtraction whose sign is read (an adder op, marked
// `compare`: its result feeds only a flag or a multiplexer, so a unit with a comparator
// could run it there; the energy model counts it apart, cost/cost_model.h); a test against
// zero reads a sign or zero flag and is free. Early-exit checks are placed in
// program order: the scheduler issues, on each unit, the first ready operation in program
// order, so a stage's check is never delayed by work of a later stage (what a designer of an
// early-exit unit does). A stage's exit cost is the cycle in which its last check completes.
#pragma once

#include "geom/kernel.h"

#include <string>
#include <vector>

namespace oprt {

enum class Fu { adder, multiplier };

struct Op {
  std::string name;
  Fu fu;
  std::vector<std::string> in;  // operations whose results it needs (registers are free)
  int exit_stage = -1;          // >= 0: this op completes the check that ends that stage
  bool compare = false;         // an adder op whose result is read only as a sign (a comparison)
};

struct OpGraph {
  std::string name;
  std::vector<std::string> stages;  // exit stage names, in order; the last one is "done"
  std::vector<Op> ops;              // program order
};

struct Schedule {
  const OpGraph* graph = nullptr;
  std::vector<int> cycle;       // per op: the cycle it issues on its unit (1-based)
  std::vector<int> exit_cycle;  // per stage: cycles spent when the unit leaves at that stage
  // A pipelined unit (modulo_schedule): a new instance enters every `ii` cycles; 0 for the
  // serial unit, which takes one instance at a time.
  int ii = 0;
  int length() const { return exit_cycle.empty() ? 0 : exit_cycle.back(); }
  // Cycle | adder | multiplier | exits, one row per cycle (a pipelined unit: the columns
  // list every op issued in the cycle, and the slots it reuses every ii cycles).
  std::string table() const;
};

// Throws std::logic_error on a malformed graph (unknown input, cycle, missing exit).
Schedule list_schedule(const OpGraph& g);

// The functional units of a pipelined unit: how many adders and multipliers, each itself
// pipelined (it accepts an operation every cycle) with the given latency in cycles.
struct FpUnits {
  int adders = 1, multipliers = 1;
  int add_latency = 1, multiply_latency = 1;
};

// The adders and multipliers a graph needs to accept one instance per cycle (II 1).
FpUnits full_units(const OpGraph& g, int add_latency = 1, int multiply_latency = 1);

// Modulo scheduling (Rau's iterative modulo scheduling, here without recurrences: every
// instance, a ray or a (ray, triangle) pair, is independent of the one before it). The
// initiation interval is the resource bound II = max(ceil(adds / adders),
// ceil(multiplies / multipliers)); ops are placed in program order, each at the earliest
// cycle after its inputs' results whose slot (cycle mod II) on a unit of its kind is free.
// In a graph without recurrences a free slot is always found within II cycles of that
// earliest cycle, so the schedule reaches the resource bound. cycle[i] is op i's issue
// cycle counted from the instance's entry (1-based); exit_cycle[k] the cycle in which the
// check ending stage k produces its result (issue + latency - 1): the unit's latency is
// length(). Throws std::logic_error on a malformed graph or zero units of a kind it needs.
Schedule modulo_schedule(const OpGraph& g, const FpUnits& units);

// The IU's operations.
const OpGraph& sphere_textbook_graph();  // the paper's form
const OpGraph& sphere_stable_graph();    // the form the model runs (geom/sphere.h)
const OpGraph& transform_graph();        // ray into the local frame (geom/affine.h)
const OpGraph& moller_graph();           // geom/triangle.h, exit stages det, u, v, t
const OpGraph& transform_watertight_graph();  // the transform plus the ray's dominant axis
const OpGraph& watertight_graph();       // geom/watertight.h, exit stages uv, w, det, t
const OpGraph& box_setup_graph();        // --accel bvh: reciprocal direction (geom/bvh.h)
const OpGraph& box_graph();              // --accel bvh: ray-box test (geom/bvh.h)
const OpGraph& top_node_graph();
// A pipelined unit's transform unit with --accel bvh: the kernel's transform, then the box
// set-up on its result.
const OpGraph& transform_box_setup_graph(Kernel k);         // --top bvh: node of a unit's tree over its spheres (ref/top_tree.h)

}  // namespace oprt
