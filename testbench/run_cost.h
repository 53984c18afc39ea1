// What a run costs: its area (once per run) and each frame's energy, from a technology
// table (--tech, testbench/tech/*.json; by default the 65 nm table built into oprt) and the
// counters the frame collected (cost/cost_model.h). It sizes each unit's object memory,
// configuration registers and ray FIFO to their peak over the run so far, so the area it
// reports can only grow as frames come in (a dynamic assignment, an unbounded FIFO). The
// sizing rules are cost/sizing.h's; this holds the table and the design across frames.
#pragma once

#include "arch/arch.h"
#include "cost/cost_model.h"
#include "cost/tech.h"
#include "stats.h"

#include <string>

#include <nlohmann/json.hpp>

namespace oprt {

class RunCost {
 public:
  // `tech_file` empty: the built-in 65 nm table.
  RunCost(const std::string& tech_file, const Arch& arch, std::size_t units, std::size_t spheres);

  // The frame's energy; also grows the design's sizes to the frame's.
  Cost frame(const FrameStats& fs);
  Cost area() const { return area_mm2(tech_, design_); }
  // For the stats header: which table, the IU's arithmetic, its operations per IU operation.
  nlohmann::json header() const;

 private:
  const Arch& arch_;
  Tech tech_;
  std::string source_;
  Design design_;
  OpCounts ops_;
};

}  // namespace oprt
