// What the technology-table fuzz target does with a table that loaded: the area and one
// frame's energy of a two-unit design at extreme but possible sizes and counts (2^40 of every
// count, a 1 TiB object memory). Every figure must be finite, or the table refused with an
// InputError naming it.
#pragma once

#include "cost/cost_model.h"
#include "cost/tech.h"

#include <cstdint>

namespace oprt::fuzz {

inline void exercise(const Tech& t) {
  Design d;
  d.units.resize(2);
  d.ray_bytes = ray_bytes(false);
  d.units[0] = {std::uint64_t{1} << 40, std::uint64_t{1} << 30, 4096, 0};
  d.units[1] = {64, 1, 1, 0};
  FrameActivity f;
  f.units.resize(2);
  for (UnitActivity& a : f.units) {
    a.work.sphere_tests = a.work.transforms = a.work.tri_stage[3] = std::uint64_t{1} << 40;
    a.memory_read_bytes = a.dram_bytes = a.fifo_pushes = a.fifo_pops = std::uint64_t{1} << 40;
  }
  f.bus_bytes = std::uint64_t{1} << 40;
  f.frame_time_s = 1e6;
  (void)area_mm2(t, d).to_json().dump();
  (void)frame_energy_j(t, d, op_counts(Kernel::moller), f).to_json().dump();
}

}  // namespace oprt::fuzz
