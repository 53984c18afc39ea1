// Hardware sizing: the design an architecture implies (the router's lanes and registers, the
// IU's arithmetic, its operations per IU operation) and, frame by frame, how large each unit's
// stores must be and what the frame did with them, from the frame's figures (timing/
// unit_run.h). Pure functions of the architecture and the counters, no SystemC: the rules the
// area and energy of cost_model.h are priced from. testbench/run_cost.cpp calls them.
#pragma once

#include "arch/arch.h"
#include "cost/cost_model.h"
#include "timing/unit_run.h"

#include <cstddef>
#include <cstdint>

namespace oprt {

// What a pipelined IU's ray store holds per ray slot: the ray (Bytes<T>::ray) and its
// local-frame copy (origin and direction); and each entry of its traversal stack (a node index).
struct StoreBytes {
  std::uint64_t ray, local_ray;
};
StoreBytes store_bytes(bool double_precision);
constexpr std::uint64_t kStackEntryBytes = 4;

// The design before any frame: the router (--route: its box-test units times its lanes, a box
// register per unit or per sphere bound), the ray's bytes, a pipelined IU's arithmetic (each
// stage's adders and multipliers; operands through pipeline registers, no register file), and
// `units` units with nothing stored yet.
Design initial_design(const Arch& arch, std::size_t units, std::size_t spheres);

// Operations per IU operation: a serial IU's by the list schedule, a pipelined IU's by its
// stages' schedules (the box set-up by the list schedule: part of the transform unit's graph).
OpCounts iu_op_counts(const Arch& arch);

// What the run adds to a unit's figures for sizing: the geometry its assignment holds and its
// configuration registers written this frame.
struct UnitHolds {
  std::uint64_t memory_capacity_bytes = 0;
  std::uint64_t config_bytes = 0;
};

// Grows a unit's sizes to this frame's (sizes are the peak over the run so far): its object
// memory (a cache: memory.sram_bytes at most), configuration registers, ray FIFO (its depth, or
// unbounded as many entries as it ever held, one at least if a ray passed), a cache's miss
// registers, a pipelined IU's ray store and traversal stacks.
void grow_unit(UnitSize& z, const Arch& arch, const timing::UnitRun& r, const UnitHolds& h);

// What a unit did with those stores this frame: its work over every ray kind, object memory
// reads and writes (a cache's fills, a pipelined IU's stack spills and fills), FIFO pushes and
// pops, register writes, DRAM bytes, miss-register, ray-store and stack accesses.
UnitActivity unit_activity(const Arch& arch, const timing::UnitRun& r, const UnitHolds& h);

// The frame's activity outside the units (units left empty): bus bytes, the router's tests
// (every ray against every bound), the frame's time.
FrameActivity frame_activity(const Arch& arch, const timing::FrameFigures& f, double frame_time_s);

}  // namespace oprt
