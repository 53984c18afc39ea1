// A technology table: the area and energy of the blocks an intersection unit is built from,
// each number with its source (docs/tech-format.md). Read from an `oprt-tech/1` JSON file
// (testbench/tech/*.json); cost/cost_model.h turns it and a run's counters into area and
// energy per frame. Plain C++, no SystemC.
//
// Every value is stored here in one unit per kind: mm2, pJ, bytes, pJ per bit and mm,
// W per mm2. The file may state a value in the unit its source uses (um2, nJ, KiB, ...):
// the loader converts, and rejects a unit of the wrong kind.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oprt {

// A quantity that grows with an SRAM's capacity, known at a few capacities and interpolated
// between them linearly in log(capacity) and log(value) (a power law between neighbours:
// CACTI's figures follow one closely over a factor of two to four).
class SizeCurve {
 public:
  struct Point {
    double bytes, value;
  };
  // Where a capacity fell: on a point, between two, or outside the table.
  enum class Range { point, interpolated, below, above };
  struct Lookup {
    double value;
    Range range;
  };

  SizeCurve() = default;
  explicit SizeCurve(std::vector<Point> points);  // capacities strictly increasing, values > 0
  bool empty() const { return points_.empty(); }
  const std::vector<Point>& points() const { return points_; }
  // Below the smallest capacity: the smallest point's value (a smaller SRAM costs less, so
  // this over-estimates). Above the largest: the last two points' power law extended (with
  // one point: that point's value). Both are flagged in `range`.
  Lookup at(double bytes) const;

 private:
  std::vector<Point> points_;
};

struct Tech {
  std::string file;  // where it was read from
  std::string name;
  std::optional<double> node_nm;

  // One functional unit: its area and the energy of one operation.
  struct Unit {
    std::optional<double> area_mm2, energy_pj;
  };
  Unit fp_add, fp_multiply, fp_compare, fp_inverse;

  struct {
    std::optional<double> area_mm2;      // one register file
    std::optional<double> energy_pj;     // one access (a read or a write of one register)
    std::optional<double> bytes;         // its capacity (for area per byte of register storage)
    std::optional<double> access_bytes;  // one register
  } register_file;

  struct {
    std::optional<double> access_bytes;  // what one access of `read_energy_pj` reads
    SizeCurve read_energy_pj;            // per access, by capacity
    SizeCurve area_mm2;                  // by capacity
  } sram;

  struct {
    std::optional<double> access_bytes;
    std::optional<double> energy_low_pj, energy_high_pj;  // per access: the source gives a range
  } dram;

  std::optional<double> wire_pj_per_bit_mm;  // on-chip wire
  std::optional<double> leakage_w_per_mm2;   // static power per area
};

// Throws InputError (file, JSON path, problem): unknown keys, a missing source, a source
// not listed under "sources", a unit of the wrong kind, a value that is not positive,
// capacities out of order.
Tech load_tech(const std::string& path);
Tech tech_from_json(const nlohmann::json& doc, const std::string& file);

}  // namespace oprt
