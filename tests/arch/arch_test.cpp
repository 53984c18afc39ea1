#include "arch/arch.h"
#include "base/error.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
Arch parse(const std::string& text) { return arch_from_json(nlohmann::json::parse(text), "arch.json"); }

void expect_error(const std::string& text, const std::string& place, const std::string& problem) {
  try {
    parse(text);
    FAIL("no error for " << text);
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == "arch.json");
    CHECK(e.place().find(place) != std::string::npos);
    CHECK(e.problem().find(problem) != std::string::npos);
  }
}
}  // namespace

TEST_CASE("arch: defaults are the paper's ideal assumptions", "[arch]") {
  const Arch a = parse(R"({"format": "oprt-arch/1"})");
  CHECK(a.ius == 32);
  CHECK(a.costs.sphere == 9);
  CHECK(a.costs.moller.transform == 19);
  CHECK(a.fifo_depth == 0);
  CHECK(a.bus.model == BusModel::ideal);
  CHECK(a.bus.lt_arbitration == LtArbitration::sync);
  CHECK(a.memory.model == MemoryModel::ideal);
  CHECK(a.gpp.cycles_per_ray == 0);
  CHECK(a.level == Level::at);
}

TEST_CASE("arch: every field is read", "[arch]") {
  const Arch a = parse(R"({"format": "oprt-arch/1", "clock_mhz": 200, "ius": 8,
    "costs": {"sphere": 13, "transform": 20, "triangle": [5, 15, 18, 23],
              "watertight": {"transform": 22, "triangle": [17, 19, 20, 26]}}, "ray_fifo_depth": 4,
    "bus": {"model": "shared", "bytes_per_cycle": 16, "arbitration_cycles": 2, "lt_arbitration": "calendar"},
    "memory": {"model": "latency", "latency_cycles": 7, "bytes_per_cycle": 32},
    "gpp": {"cycles_per_ray": 3, "cycles_per_hit": 40}, "level": "lt", "quantum": "250 ns",
    "balance": "sa_n", "subdivide": 8, "kernel": "watertight", "precision": "double"})");
  CHECK(a.cycle_ns() == 5);
  CHECK(a.ius == 8);
  CHECK(a.costs.moller.transform == 20);
  CHECK(a.costs.moller.tri_stage[3] == 23);
  CHECK(a.costs.watertight.transform == 22);
  CHECK(a.costs.watertight.tri_stage[0] == 17);
  CHECK(a.kernel == Kernel::watertight);
  CHECK(a.kernel_costs().tri_stage[3] == 26);  // the run charges the kernel it uses
  CHECK(a.fifo_depth == 4);
  CHECK(a.bus.bytes_per_cycle == 16);
  CHECK(a.bus.arbitration_cycles == 2);
  CHECK(a.bus.lt_arbitration == LtArbitration::calendar);
  CHECK(a.memory.latency_cycles == 7);
  CHECK(a.gpp.cycles_per_hit == 40);
  CHECK(a.level == Level::lt);
  CHECK(a.quantum_ns == 250);
  CHECK(a.balance == "sa_n");
  CHECK(a.subdivide == 8);
  CHECK(a.precision == "double");
  const Arch b = parse(R"({"format": "oprt-arch/1", "accel": "bvh", "costs": {"box": 9, "box_setup": 20}})");
  CHECK(b.accel == "bvh");
  CHECK(b.costs.box == 9);
  CHECK(b.costs.box_setup == 20);
  CHECK(to_json(b)["costs"]["box"] == 9);
}

TEST_CASE("arch: the tree over each unit's spheres and the object memory's capacity", "[arch][top][cache]") {
  const Arch d = parse(R"({"format": "oprt-arch/1"})");
  CHECK(d.top == "flat");               // every sphere, as the paper
  CHECK(d.memory.sram_bytes == 0);      // holds any assignment
  CHECK(d.costs.node == scheduled_costs().node);
  const Arch a = parse(R"({"format": "oprt-arch/1", "top": "bvh", "costs": {"node": 11},
    "gpp": {"cycles_per_node": 35},
    "memory": {"sram_bytes": 16384, "cache": {"line_bytes": 128, "ways": 8, "replacement": "fifo", "misses_outstanding": 2},
               "dram": {"latency_cycles": 90, "bytes_per_cycle": 4, "units_per_channel": 2, "path": "bus"}}})");
  CHECK(a.top_tree());
  CHECK(a.costs.node == 11);
  CHECK(a.gpp.cycles_per_node == 35);
  CHECK(a.memory.model == MemoryModel::ideal);  // "model" may be left out
  CHECK(a.memory.sram_bytes == 16384);
  CHECK(a.memory.cache.line_bytes == 128);
  CHECK(a.memory.cache.ways == 8);
  CHECK(a.memory.cache.replacement == CacheReplacement::fifo);
  CHECK(a.memory.cache.misses_outstanding == 2);
  CHECK(a.memory.dram.latency_cycles == 90);
  CHECK(a.memory.dram.bytes_per_cycle == 4);
  CHECK(a.memory.dram.units_per_channel == 2);
  CHECK(a.memory.dram.path == DramPath::bus);
  // What stats.json records reads back as the same architecture.
  const nlohmann::json j = to_json(a);
  CHECK(j["top"] == "bvh");
  CHECK(j["memory"]["sram_bytes"] == 16384);
  CHECK(j["memory"]["cache"]["replacement"] == "fifo");
  CHECK(j["memory"]["dram"]["path"] == "bus");
  CHECK(j["gpp"]["cycles_per_node"] == 35);
}

TEST_CASE("arch: bad files fail with the place and the problem", "[arch]") {
  expect_error(R"({"format": "oprt-arch/1", "ius": 0})", "/ius", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"sphere": -1}})", "/costs/sphere", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"watertight": {"triangle": [1, 2]}}})",
               "/costs/watertight/triangle", "expected 4 cycle counts (exit stages uv, w, det, t), found 2");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"watertight": {"sphere": 3}}})", "/costs/watertight",
               "sphere");
  expect_error(R"({"format": "oprt-arch/1", "kernel": "plucker"})", "/kernel", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"triangle": [4, 22]}})", "/costs/triangle", "expected 4");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"box": -3}})", "/costs/box", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "costs": {"nodes": 3}})", "/costs/nodes", "unknown key");
  expect_error(R"({"format": "oprt-arch/1", "top": "kd"})", "/top", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"sram_bytes": -1}})", "/memory/sram_bytes", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"sram_bytes": 100}})", "/memory/sram_bytes",
               "smaller than one cache set (line_bytes x ways = 256 bytes)");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"cache": {"line_bytes": 48}}})", "/memory/cache/line_bytes",
               "power of two");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"cache": {"replacement": "lfu"}}})",
               "/memory/cache/replacement", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"dram": {"units_per_channel": 0}}})",
               "/memory/dram/units_per_channel", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "memory": {"dram": {"path": "noc"}}})", "/memory/dram/path",
               "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "accel": "kd"})", "/accel", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "bus": {"model": "crossbar"}})", "/bus/model", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "bus": {"model": "shared", "bytes_per_cycle": 0}})",
               "/bus/bytes_per_cycle", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "bus": {"model": "shared", "lt_arbitration": "lottery"}})", "/bus/lt_arbitration",
               "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "fifo": 4})", "/fifo", "unknown key");
  expect_error(R"({"format": "oprt-arch/1", "clock_mhz": "fast"})", "/clock_mhz", "expected a number");
  expect_error(R"({"format": "oprt-arch/2"})", "/format", "unsupported");
  expect_error(R"({"ius": 4})", "/", "missing required key \"format\"");
  CHECK_THROWS_AS(parse(R"({"format": "oprt-arch/1", "quantum": "10 parsecs"})"), InputError);
}

TEST_CASE("arch: time strings", "[arch]") {
  CHECK(parse_time_ns("10 ns", "q") == 10);
  CHECK(parse_time_ns("1us", "q") == 1000);
  CHECK(parse_time_ns("100 us", "q") == 100000);
  CHECK(parse_time_ns("2.5ms", "q") == 2.5e6);
  CHECK_THROWS_AS(parse_time_ns("-1 ns", "q"), InputError);
  CHECK_THROWS_AS(parse_time_ns("ns", "q"), InputError);
}

TEST_CASE("arch: the IU section: serial by default, pipelined with its units, stacks and latencies", "[arch][pipelined]") {
  const Arch d = parse(R"({"format": "oprt-arch/1"})");
  CHECK(d.iu.model == IuModel::serial);
  CHECK(to_json(d)["iu"]["model"] == "serial");
  const Arch a = parse(R"({"format": "oprt-arch/1", "iu": {"model": "pipelined", "rays_in_flight": 5,
    "stack": {"depth": 3, "overflow_cycles": 25}, "fp_latency": {"add": 3, "multiply": 4}, "sphere": {"adders": 2},
    "box": {"multipliers": 5}, "node": {"adders": 4}, "triangle": {"adders": 6, "multipliers": 7}}})");
  CHECK(a.iu.model == IuModel::pipelined);
  CHECK(a.iu.rays_in_flight == 5);
  CHECK(a.iu.stack_depth == 3);
  CHECK(a.iu.stack_overflow_cycles == 25);
  CHECK(a.iu.box.multipliers == 5);
  CHECK(a.iu.box.adders == 0);
  CHECK(a.iu.node.adders == 4);
  CHECK(a.iu.add_latency == 3);
  CHECK(a.iu.multiply_latency == 4);
  CHECK(a.iu.sphere.adders == 2);
  CHECK(a.iu.sphere.multipliers == 0);  // 0: enough for II 1
  CHECK(a.iu.triangle.multipliers == 7);
  CHECK(to_json(a)["iu"]["fp_latency"]["multiply"] == 4);
  const nlohmann::json round_trip = {{"format", "oprt-arch/1"}, {"iu", to_json(a)["iu"]}};  // what stats.json records
  CHECK(arch_from_json(round_trip, "x").iu.triangle.adders == 6);
  CHECK(arch_from_json(round_trip, "x").iu.stack_depth == 3);
  CHECK(arch_from_json(round_trip, "x").iu.box.multipliers == 5);
  expect_error(R"({"format": "oprt-arch/1", "iu": {"model": "vliw"}})", "/iu/model", "unknown value");
  expect_error(R"({"format": "oprt-arch/1", "iu": {"rays_in_flight": 0}})", "/iu/rays_in_flight", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "iu": {"fp_latency": {"divide": 9}}})", "/iu/fp_latency/divide", "unknown key");
  expect_error(R"({"format": "oprt-arch/1", "iu": {"transform": {"adders": -1}}})", "/iu/transform/adders", "out of range");
  expect_error(R"({"format": "oprt-arch/1", "iu": {"stack": {"depth": 0}}})", "/iu/stack/depth", "out of range");
  // The queues between units of the pipeline before it picked among its rays in flight.
  expect_error(R"({"format": "oprt-arch/1", "iu": {"queue_depth": 4}})", "/iu/queue_depth", "rays_in_flight");
  // Every combination composes.
  const Arch all = parse(R"({"format": "oprt-arch/1", "accel": "bvh", "top": "bvh", "memory": {"sram_bytes": 16384},
    "iu": {"model": "pipelined"}})");
  CHECK_NOTHROW(check_arch(all));
}
