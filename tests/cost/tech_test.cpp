#include "cost/tech.h"
#include "base/error.h"
#include "base/json_in.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace oprt;

namespace {
const std::string kDir = std::string(OPRT_SOURCE_DIR) + "/testbench/tech/";

// A minimal valid table; tests break one thing in it.
nlohmann::json minimal() {
  return nlohmann::json::parse(R"({
    "format": "oprt-tech/1", "name": "test",
    "sources": {"s": {"cite": "a paper", "where": "table 1"}},
    "fp_add": {"area": {"value": 3311, "unit": "um2", "source": "s", "basis": "quoted"},
               "energy": {"value": 7.4, "unit": "pJ", "source": "s", "basis": "quoted"}},
    "sram": {"access": {"value": 8, "unit": "bytes", "source": "s", "basis": "quoted"},
             "read_energy": [
               {"capacity": {"value": 8, "unit": "KiB", "source": "s", "basis": "quoted"},
                "energy": {"value": 10, "unit": "pJ", "source": "s", "basis": "quoted"}},
               {"capacity": {"value": 32, "unit": "KiB", "source": "s", "basis": "quoted"},
                "energy": {"value": 20, "unit": "pJ", "source": "s", "basis": "quoted"}}]}
  })");
}

// The InputError a broken table raises, as "place: problem".
std::string error_of(const nlohmann::json& doc) {
  try {
    tech_from_json(doc, "t.json");
  } catch (const InputError& e) {
    CHECK(e.file() == "t.json");
    return e.place() + ": " + e.problem();
  }
  return "no error";
}
}  // namespace

TEST_CASE("tech: the shipped tables load, in the model's units", "[tech]") {
  const Tech t65 = load_tech(kDir + "65nm.json");
  CHECK(*t65.node_nm == 65);
  CHECK(*t65.fp_add.area_mm2 == Approx(0.003311));          // written 3311 um2
  CHECK(*t65.fp_add.energy_pj == Approx(7.4));
  CHECK(*t65.register_file.energy_pj == Approx(7.89613));   // written 0.00789613 nJ
  CHECK(*t65.sram.access_bytes == 32);
  CHECK(t65.sram.read_energy_pj.points().size() == 14);
  CHECK(t65.sram.read_energy_pj.points().front().bytes == 1024);            // written 1 KiB
  CHECK(t65.sram.read_energy_pj.points().front().value == Approx(57.741));  // written 0.057741 nJ
  CHECK(t65.sram.area_mm2.points().back().bytes == 8.0 * 1024 * 1024);      // written 8 MiB
  CHECK(!t65.leakage_w_per_mm2);

  const Tech t45 = load_tech(kDir + "45nm.json");
  CHECK(*t45.fp_add.energy_pj == Approx(0.9));
  CHECK(*t45.fp_multiply.energy_pj == Approx(3.7));
  CHECK(t45.sram.read_energy_pj.at(32 * 1024).value == Approx(20));
  CHECK(t45.sram.read_energy_pj.at(1024 * 1024).value == Approx(100));
  CHECK(*t45.dram.energy_low_pj == Approx(1300));
  CHECK(*t45.dram.energy_high_pj == Approx(2600));
  CHECK(!t45.register_file.energy_pj);  // Horowitz gives none
  // Areas at 45 nm are the 65 nm ones scaled by (45/65)^2.
  CHECK(*t45.fp_multiply.area_mm2 == Approx(*t65.fp_multiply.area_mm2 * (45.0 / 65) * (45.0 / 65)).epsilon(1e-4));
}

TEST_CASE("tech: SRAM figures between table sizes follow the power law of the neighbours", "[tech]") {
  const SizeCurve c({{8 * 1024, 10}, {32 * 1024, 20}, {1024 * 1024, 100}});
  // 16 KiB is halfway between 8 and 32 KiB in log(size): 10 x 2^(1/2).
  const auto mid = c.at(16 * 1024);
  CHECK(mid.value == Approx(14.142135623730951));
  CHECK(mid.range == SizeCurve::Range::interpolated);
  CHECK(c.at(32 * 1024).range == SizeCurve::Range::point);
  // Below the smallest size: the smallest size's value, flagged.
  CHECK(c.at(1024).value == 10);
  CHECK(c.at(1024).range == SizeCurve::Range::below);
  // Above: the last segment extended. 2 MiB is 1/5 of the way from 32 KiB to 1 MiB again
  // (log 2 / log 32), so 100 x 5^(1/5).
  CHECK(c.at(2 * 1024 * 1024).value == Approx(137.97296614612148));
  CHECK(c.at(2 * 1024 * 1024).range == SizeCurve::Range::above);
  // The 65 nm table: 48 KiB between its 32 KiB (0.169293 nJ) and 64 KiB (0.237390 nJ) points.
  const Tech t65 = load_tech(kDir + "65nm.json");
  const double t = std::log(1.5) / std::log(2.0);
  CHECK(t65.sram.read_energy_pj.at(48 * 1024).value == Approx(169.293 * std::pow(237.390 / 169.293, t)));
}

TEST_CASE("tech: a bad table is rejected with the place named", "[tech][errors]") {
  CHECK(error_of(minimal()) == "no error");
  {
    auto d = minimal();
    d["fp_add"]["energy"].erase("source");
    CHECK(error_of(d) == "/fp_add/energy: missing required key \"source\"");
  }
  {
    auto d = minimal();
    d["fp_add"]["energy"]["source"] = "nowhere";
    CHECK(error_of(d) == "/fp_add/energy/source: unknown source \"nowhere\" (list it under /sources)");
  }
  {
    auto d = minimal();
    d["fp_add"]["power"] = d["fp_add"]["energy"];
    CHECK(error_of(d).rfind("/fp_add/power: unknown key \"power\"", 0) == 0);
  }
  {
    auto d = minimal();
    d["fp_add"]["energy"]["value"] = -7.4;
    CHECK(error_of(d) == "/fp_add/energy/value: must be positive, found -7.4");
  }
  {
    auto d = minimal();
    d["fp_add"]["area"]["unit"] = "pJ";
    CHECK(error_of(d) == "/fp_add/area/unit: unit \"pJ\" is not an area (expected one of: mm2, um2)");
  }
  {
    auto d = minimal();
    d["fp_add"]["energy"]["basis"] = "derived";
    CHECK(error_of(d) == "/fp_add/energy: a derived value needs a \"note\" saying how it was obtained");
  }
  {
    auto d = minimal();
    d["sram"]["read_energy"][1]["capacity"]["value"] = 8;
    CHECK(error_of(d) ==
          "/sram/read_energy/1/capacity: capacities must increase (this one is not larger than the previous point's)");
  }
  {
    auto d = minimal();
    d["sram"].erase("access");
    CHECK(error_of(d) == "/sram: a \"read_energy\" needs \"access\" (the bytes one access reads)");
  }
  {
    auto d = minimal();
    d["sources"]["s"].erase("where");
    CHECK(error_of(d) == "/sources/s: missing required key \"where\"");
  }
  {
    auto d = minimal();
    d["format"] = "oprt-tech/2";
    CHECK(error_of(d) == "/format: unsupported format \"oprt-tech/2\" (expected oprt-tech/1)");
  }
}
