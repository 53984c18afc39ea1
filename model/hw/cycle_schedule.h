// The intersection unit's arithmetic: one adder/subtractor and one multiplier, each taking
// one cycle per operation (the paper's assumption). Every IU operation is written here as
// the graph of its additions and multiplications, and a list scheduler places them on the
// two units cycle by cycle. The cycle counts the architecture charges by default come from
// these schedules (cycle_costs.h); `oprt_schedules` prints them as tables.
//
// Conventions. A comparison is a subtraction whose sign is read (an adder op, marked
// `compare`: its result feeds only a flag or a multiplexer, so a unit with a comparator
// could run it there; the energy model counts it apart, hw/cost_model.h); a test against
// zero reads a sign or zero flag and is free. Early-exit checks are placed in
// program order: the scheduler issues, on each unit, the first ready operation in program
// order, so a stage's check is never delayed by work of a later stage (what a designer of an
// early-exit unit does). A stage's exit cost is the cycle in which its last check completes.
#pragma once

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
  std::vector<int> cycle;       // per op: the cycle it occupies its unit (1-based)
  std::vector<int> exit_cycle;  // per stage: cycles spent when the unit leaves at that stage
  int length() const { return exit_cycle.empty() ? 0 : exit_cycle.back(); }
  // Cycle | adder | multiplier | exits, one row per cycle.
  std::string table() const;
};

// Throws std::logic_error on a malformed graph (unknown input, cycle, missing exit).
Schedule list_schedule(const OpGraph& g);

// The IU's operations.
const OpGraph& sphere_textbook_graph();  // the paper's form
const OpGraph& sphere_stable_graph();    // the form the model runs (geom/sphere.h)
const OpGraph& transform_graph();        // ray into the local frame (geom/affine.h)
const OpGraph& moller_graph();           // geom/triangle.h, exit stages det, u, v, t
const OpGraph& transform_watertight_graph();  // the transform plus the ray's dominant axis
const OpGraph& watertight_graph();       // geom/watertight.h, exit stages uv, w, det, t
const OpGraph& box_setup_graph();        // --accel bvh: reciprocal direction (geom/bvh.h)
const OpGraph& box_graph();              // --accel bvh: ray-box test (geom/bvh.h)

}  // namespace oprt
