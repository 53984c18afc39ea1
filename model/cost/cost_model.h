// First-order area and energy of a configuration, from a technology table (cost/tech.h) and
// the counters a run collects. Plain C++: the stats writer calls it once per run (area)
// and once per frame (energy). docs/tech-format.md says what each component charges and
// where it is only first order.
//
// Energy per frame, by component:
//   fp_add, fp_multiply, fp_compare, fp_inverse  the operations of the operation graphs
//       (cycle_schedule.cpp) times the work counts; a test that leaves at an exit stage
//       pays for the operations its unit had issued by then. A comparison runs on the
//       adder (at the adder's energy) unless the IU has comparators.
//   register_file            3 accesses per operation (2 operand reads, 1 write), as
//                            SimTRaX charges an instruction (its sim/main.cc); IuUnits
//                            sets another count.
//   object_memory_reads      bytes read / access width x the energy of one access of an
//                            SRAM of that unit's object-memory size (interpolated).
//   object_memory_writes     geometry loaded during the frame, charged as reads.
//   ray_fifo                 each push and each pop moves one ray: an access of an SRAM of
//                            the FIFO's size per access width.
//   configuration            bytes written to configuration registers, one register-file
//                            access per register.
//   pipeline_buffers         a pipelined IU's queues and store of rays in flight: bytes
//                            read and written, one register-file access per register.
//   bus                      bytes x 8 x wire energy per bit and mm x the bus length, taken
//                            as the side of a square die of the configuration's area.
//   dram                     bytes / access x the middle of the table's range.
//   leakage                  area x static power density x frame time.
// Area, by component: the FP units and register files of each IU, the configuration
// registers (register-file area per byte), the object memories sized to what their
// assignment holds at its peak, the ray FIFOs, a pipelined IU's buffers (register-file area
// per byte); each summed over the units.
// A component the table has no number for is reported as null (not charged) with a note;
// a capacity outside the table's SRAM sizes is noted too.
#pragma once

#include "geom/kernel.h"
#include "arch/cycle_schedule.h"
#include "cost/tech.h"
#include "ref/work.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oprt {

struct FpOps {
  std::uint64_t add = 0, multiply = 0, compare = 0, inverse = 0;

  std::uint64_t total() const { return add + multiply + compare + inverse; }
  FpOps& operator+=(const FpOps& o) {
    add += o.add, multiply += o.multiply, compare += o.compare, inverse += o.inverse;
    return *this;
  }
  FpOps times(std::uint64_t n) const { return {add * n, multiply * n, compare * n, inverse * n}; }
  bool operator==(const FpOps& o) const {
    return add == o.add && multiply == o.multiply && compare == o.compare && inverse == o.inverse;
  }
};

// The operations a unit has issued by the cycle it leaves the operation at `stage` (an
// index into the graph's stages; the last is "done"). A unit that issues a later stage's
// independent work early, as the serial IU's list schedule does, has spent that energy
// even when the test then exits.
FpOps ops_until_exit(const Schedule& s, int stage);

// Operations per IU operation, by exit stage for a triangle test.
struct OpCounts {
  FpOps sphere, transform, triangle[kTriStages], box_setup, box, node;
};

// From the graphs the model runs with kernel k (the stable sphere test, geom/sphere.h),
// scheduled by `schedule` (the serial IU's list schedule by default; a pipelined unit
// passes its own).
OpCounts op_counts(Kernel k, const std::function<Schedule(const OpGraph&)>& schedule = list_schedule);

// The operations of a frame's work: all of them, and split by what runs them: the box
// set-ups and box tests (--accel bvh), the node tests of a unit's tree (--top bvh), the rest.
FpOps ops_of(const OpCounts& per_op, const WorkCounts& work);
struct WorkOps {
  FpOps core, box, node;
};
WorkOps work_ops(const OpCounts& per_op, const WorkCounts& work);

// The arithmetic inside one intersection unit. The default is the paper's serial IU: one
// adder/subtractor, one multiplier, one register file.
struct IuUnits {
  int adders = 1, multipliers = 1;
  int comparators = 0;  // 0: comparisons run on an adder
  int inverters = 0;
  // A pipelined IU's box unit (--accel bvh) and node unit (--top bvh), apart from the
  // adders and multipliers above (a serial IU runs those tests on its one adder and multiplier).
  int box_adders = 0, box_multipliers = 0, node_adders = 0, node_multipliers = 0;
  int register_files = 1;
  // Register-file accesses per FP operation: 2 operand reads and a write when every operand
  // comes from the register file (SimTRaX's rule); a pipelined unit that forwards operands
  // through pipeline registers makes fewer.
  double register_accesses_per_op = 3;
};

// What each unit is built with (for area, and for the energy of an access).
struct UnitSize {
  std::uint64_t object_memory_bytes = 0;  // what its assignment holds at its peak over the run
  std::uint64_t fifo_bytes = 0;           // ray FIFO capacity (depth x ray bytes; peak occupancy if unbounded)
  std::uint64_t config_bytes = 0;         // configuration registers for its spheres at the peak
  std::uint64_t buffer_bytes = 0;         // a pipelined IU's store of rays in flight (registers)
  std::uint64_t stack_bytes = 0;          // a pipelined IU's traversal stacks, one per ray slot (registers)
  std::uint64_t miss_register_bytes = 0;  // a cache's miss registers: misses_outstanding x (address + line)
};

struct Design {
  IuUnits iu;
  std::vector<UnitSize> units;  // one per instantiated IU
  std::uint32_t ray_bytes = 0;  // one FIFO entry (Bytes<T>::ray)
  bool double_precision = false;
  // --route: the GPP's router, a box-test unit with its adders and multipliers, and a
  // register per unit bound.
  int router_adders = 0, router_multipliers = 0;
  std::uint64_t router_register_bytes = 0;
};

// One unit's counters for one frame.
struct UnitActivity {
  WorkCounts work;  // every ray kind
  std::uint64_t memory_read_bytes = 0;
  std::uint64_t memory_write_bytes = 0;  // geometry loaded into its object memory this frame
  std::uint64_t fifo_pushes = 0, fifo_pops = 0;
  std::uint64_t config_write_bytes = 0;
  std::uint64_t dram_bytes = 0;
  std::uint64_t buffer_access_bytes = 0;  // a pipelined IU's ray-store reads and writes
  std::uint64_t stack_access_bytes = 0;   // its traversal stacks' pushes and pops
  std::uint64_t miss_register_access_bytes = 0;  // a cache's miss registers: each miss's line written and read
};

struct FrameActivity {
  std::vector<UnitActivity> units;  // in the order of Design::units
  std::uint64_t router_tests = 0;   // --route: unit bounds the router tested (a box test and a register read each)
  std::uint64_t bus_bytes = 0;
  double frame_time_s = 0;  // makespan at the architecture's clock
};

// A total and its components. A component is null when the table has no number for it
// and the frame needed one (it is then left out of the total, and `notes` says so).
struct Cost {
  struct Component {
    std::string name;
    std::optional<double> value;
  };
  double total = 0;
  std::vector<Component> components;
  std::vector<std::string> notes;

  std::optional<double> of(const std::string& name) const;
  // {"total": ..., <component>: value or null, ...}
  nlohmann::json to_json() const;
};

Cost area_mm2(const Tech& tech, const Design& d);
Cost frame_energy_j(const Tech& tech, const Design& d, const OpCounts& per_op, const FrameActivity& f);

// Sizes as the hardware stores them (hw/payloads.h, geom/bvh.h).
std::uint64_t object_memory_bytes(std::uint64_t triangles, std::uint64_t bvh_nodes, Kernel k, bool double_precision);
std::uint64_t config_bytes(std::uint64_t spheres, bool double_precision);
std::uint32_t ray_bytes(bool double_precision);

}  // namespace oprt
