#include "cost/cost_model.h"
#include "cost/tech.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace oprt;

namespace {
const std::string kDir = std::string(OPRT_SOURCE_DIR) + "/testbench/tech/";

bool has_note(const Cost& c, const std::string& start) {
  for (const auto& n : c.notes)
    if (n.rfind(start, 0) == 0) return true;
  return false;
}

// A design of n serial units with nothing stored.
Design serial_units(std::size_t n) {
  Design d;
  d.units.resize(n);
  d.ray_bytes = ray_bytes(false);
  return d;
}
}  // namespace

TEST_CASE("cost: operations per IU operation, counted from the graphs", "[cost]") {
  const OpCounts m = op_counts(Kernel::moller);
  // The stable sphere test (geom/sphere.h): 10 multiplies, 12 adder ops of which the last,
  // (l.l - r^2) + b^2 read only for its sign, is a comparison.
  CHECK(m.sphere == FpOps{11, 10, 1, 0});
  // The transform: 3 rows of 3 multiplies and 3 adds (o'), 3 of 3 and 2 (d').
  CHECK(m.transform == FpOps{15, 18, 0, 0});
  // A Moller test that runs to the end: 21 multiplies and 18 adder ops, 3 of them the
  // comparisons det-u-v, tmax*det-t' and the nearest-so-far test.
  CHECK(m.triangle[3] == FpOps{15, 21, 3, 0});
  // One that leaves at 'det' (cycle 4) has paid for what the list schedule issued in
  // cycles 1-4: on the adder tvx, tvy, det', det; on the multiplier d.n's three products
  // and, in cycle 4, tvy*dz (the first ready multiply in program order).
  CHECK(m.triangle[0] == FpOps{4, 4, 0, 0});
  // Box set-up: two Newton-Raphson steps per axis, r' = r (2 - d r): 12 multiplies, 6 adds.
  CHECK(m.box_setup == FpOps{6, 12, 0, 0});
  // Box test: 6 slab subtractions, 6 comparisons (max, min, the limit, the final test), 7 multiplies.
  CHECK(m.box == FpOps{6, 7, 6, 0});

  const OpCounts w = op_counts(Kernel::watertight);
  CHECK(w.transform == FpOps{15, 18, 2, 0});  // and two comparisons choosing the dominant axis
  CHECK(w.triangle[3] == FpOps{22, 25, 2, 0});
  // The serial IU has no inverse unit: no graph uses one.
  for (int s = 0; s < kTriStages; ++s) CHECK(w.triangle[s].inverse == 0);

  // A frame's operations: per-operation counts times the work counts.
  WorkCounts work;
  work.sphere_tests = 2;
  work.transforms = 1;
  work.tri_stage[0] = 3;  // three exits at det
  work.tri_stage[3] = 1;  // one full test
  CHECK(ops_of(m, work) == FpOps{2 * 11 + 15 + 3 * 4 + 15, 2 * 10 + 18 + 3 * 4 + 21, 2 * 1 + 3, 0});
}

TEST_CASE("cost: the energy of one sphere test at 65 nm, by hand", "[cost]") {
  const Tech t = load_tech(kDir + "65nm.json");
  const Design d = serial_units(1);
  FrameActivity f;
  f.units.resize(1);
  f.units[0].work.sphere_tests = 1;
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  // 11 adds and the comparison on the adder at 7.4 pJ, 10 multiplies at 14.2 pJ, and 3
  // register-file accesses (2 reads, 1 write) per operation at 7.89613 pJ.
  CHECK(*e.of("fp_add") == Approx(11 * 7.4e-12));
  CHECK(*e.of("fp_compare") == Approx(1 * 7.4e-12));
  CHECK(*e.of("fp_multiply") == Approx(10 * 14.2e-12));
  CHECK(*e.of("register_file") == Approx(3 * 22 * 7.89613e-12));
  CHECK(*e.of("object_memory_reads") == 0);
  CHECK(*e.of("ray_fifo") == 0);
  CHECK(*e.of("bus") == 0);      // no bytes moved: no wire energy needed
  CHECK(*e.of("leakage") == 0);  // no time passed
  CHECK(e.total == Approx((12 * 7.4 + 10 * 14.2 + 3 * 22 * 7.89613) * 1e-12));
  CHECK(e.notes.empty());

  // With a comparator in the unit, the comparison costs a comparator's 0.54 pJ.
  Design with_cmp = d;
  with_cmp.iu.comparators = 1;
  CHECK(*frame_energy_j(t, with_cmp, op_counts(Kernel::moller), f).of("fp_compare") == Approx(0.54e-12));
  // A unit that forwards operands and only writes results: one access per operation.
  Design forwarding = d;
  forwarding.iu.register_accesses_per_op = 1;
  CHECK(*frame_energy_j(t, forwarding, op_counts(Kernel::moller), f).of("register_file") == Approx(22 * 7.89613e-12));
}

TEST_CASE("cost: memory, FIFO and configuration energy by hand", "[cost]") {
  const Tech t = load_tech(kDir + "65nm.json");
  Design d = serial_units(2);
  d.units[0] = {64 * 1024, 16 * 36, 68};  // a 64 KiB object memory (a table point), 16 rays of FIFO
  d.units[1] = {48 * 1024, 16 * 36, 68};
  FrameActivity f;
  f.units.resize(2);
  f.units[0].memory_read_bytes = 48;    // one Moller triangle
  f.units[1].memory_read_bytes = 96;
  f.units[0].fifo_pushes = f.units[0].fifo_pops = 1;
  f.units[0].config_write_bytes = 68;
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  // 48 bytes = 1.5 accesses of 32 bytes at 237.390 pJ (64 KiB); 96 bytes = 3 accesses at
  // the 48 KiB interpolation between 169.293 pJ (32 KiB) and 237.390 pJ (64 KiB).
  const double e48k = t.sram.read_energy_pj.at(48 * 1024).value;
  CHECK(*e.of("object_memory_reads") == Approx((1.5 * 237.390 + 3 * e48k) * 1e-12));
  // A push and a pop of a 36-byte ray in a 576-byte FIFO: below the table's 1 KiB SRAM, so
  // registers: 2 x 9 register accesses of 4 bytes at 7.89613 pJ, and noted.
  CHECK(*e.of("ray_fifo") == Approx(2 * 9 * 7.89613e-12));
  CHECK(has_note(e, "ray_fifo: 1 ray FIFOs smaller than the table's smallest SRAM (1 KiB) are registers"));
  // A FIFO of 64 rays (2304 bytes) is an SRAM: 36/32 accesses each way at the 2 to 4 KiB interpolation.
  Design deep = d;
  deep.units[0].fifo_bytes = 64 * 36;
  const double e2304 = t.sram.read_energy_pj.at(2304).value;
  CHECK(*frame_energy_j(t, deep, op_counts(Kernel::moller), f).of("ray_fifo") == Approx(2 * 36.0 / 32 * e2304 * 1e-12));
  // 68 configuration bytes: 17 register writes.
  CHECK(*e.of("configuration") == Approx(17 * 7.89613e-12));
}

TEST_CASE("cost: the area of a two-unit configuration at 65 nm, by hand", "[cost]") {
  const Tech t = load_tech(kDir + "65nm.json");
  Design d = serial_units(2);
  d.units[0] = {64 * 1024, 16 * 36, 68};
  d.units[1] = {32 * 1024, 16 * 36, 68};
  const Cost a = area_mm2(t, d);
  CHECK(*a.of("fp_adders") == Approx(2 * 0.003311));
  CHECK(*a.of("fp_multipliers") == Approx(2 * 0.010327));
  CHECK(*a.of("fp_comparators") == 0);
  CHECK(*a.of("fp_inverters") == 0);
  CHECK(*a.of("register_files") == Approx(2 * 0.0147665));
  CHECK(*a.of("configuration_registers") == Approx(136 * 0.0147665 / 512));  // register-file area per byte
  CHECK(*a.of("object_memories") == Approx(0.656136 + 0.328905));            // the 64 and 32 KiB points
  // 576 bytes, below the 1 KiB SRAM: registers, at the register file's area per byte.
  CHECK(*a.of("ray_fifos") == Approx(2 * 576 * 0.0147665 / 512));
  CHECK(a.total == Approx(2 * (0.003311 + 0.010327 + 0.0147665) + 136 * 0.0147665 / 512 + 0.656136 + 0.328905 +
                          2 * 576 * 0.0147665 / 512));
  CHECK(has_note(a, "ray_fifos: 2 ray FIFOs smaller"));

  // A pipelined unit with more FP units: the area counts them per unit.
  Design p = d;
  p.iu = {4, 6, 2, 1, 1};
  const Cost ap = area_mm2(t, p);
  CHECK(*ap.of("fp_adders") == Approx(2 * 4 * 0.003311));
  CHECK(*ap.of("fp_multipliers") == Approx(2 * 6 * 0.010327));
  CHECK(*ap.of("fp_comparators") == Approx(2 * 2 * 0.000722));
  CHECK(*ap.of("fp_inverters") == Approx(2 * 1 * 0.112818));
}

TEST_CASE("cost: what a table lacks is reported as not charged, never as zero", "[cost]") {
  const Tech t = load_tech(kDir + "45nm.json");
  Design d = serial_units(1);
  d.units[0] = {16 * 1024, 1024, 68};
  FrameActivity f;
  f.units.resize(1);
  f.units[0].work.sphere_tests = 1;
  f.units[0].memory_read_bytes = 16;
  f.bus_bytes = 36;
  f.frame_time_s = 1e-3;
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  CHECK(*e.of("fp_add") == Approx(11 * 0.9e-12));
  CHECK(*e.of("fp_multiply") == Approx(10 * 3.7e-12));
  CHECK(!e.of("register_file"));  // Horowitz gives no register-file energy
  CHECK(!e.of("bus"));            // nor a wire energy
  CHECK(!e.of("leakage"));        // nor leakage
  CHECK(has_note(e, "register_file: not charged"));
  CHECK(has_note(e, "bus: not charged"));
  CHECK(has_note(e, "leakage: not charged"));
  // 16 bytes: two 64-bit reads of a 16 KiB SRAM, 10 x 2^(1/2) pJ each.
  CHECK(*e.of("object_memory_reads") == Approx(2 * 14.142135623730951e-12));
  CHECK(e.total == Approx((12 * 0.9 + 10 * 3.7 + 2 * 14.142135623730951) * 1e-12));
  const auto j = e.to_json();
  CHECK(j["register_file"].is_null());
  CHECK(j["total"].get<double>() == Approx(e.total));
}

TEST_CASE("cost: wire and leakage scale with the configuration's area", "[cost]") {
  Tech t = load_tech(kDir + "65nm.json");
  t.wire_pj_per_bit_mm = 0.1;   // test values, not from any source
  t.leakage_w_per_mm2 = 0.01;
  Design d = serial_units(1);
  d.units[0] = {64 * 1024, 0, 0};
  FrameActivity f;
  f.units.resize(1);
  f.bus_bytes = 10;
  f.frame_time_s = 2e-3;
  const double area = area_mm2(t, d).total;
  CHECK(area == Approx(0.003311 + 0.010327 + 0.0147665 + 0.656136));
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  CHECK(*e.of("bus") == Approx(80 * 0.1e-12 * std::sqrt(area)));  // 80 bits across the die's side
  CHECK(*e.of("leakage") == Approx(0.01 * area * 2e-3));
}

TEST_CASE("cost: sizes as the hardware stores them", "[cost]") {
  CHECK(object_memory_bytes(100, 10, Kernel::moller, false) == 100 * 48 + 10 * 32);
  CHECK(object_memory_bytes(100, 0, Kernel::watertight, true) == 100 * 72);
  CHECK(config_bytes(3, false) == 3 * 68);
  CHECK(ray_bytes(false) == 36);
  CHECK(ray_bytes(true) == 64);
}

TEST_CASE("cost: a pipelined unit's early exit saves only what it had not yet issued", "[cost][pipelined]") {
  // Fully pipelined Moller (a unit per op, latency 1): det is known in cycle 3, by which
  // time every op with its inputs ready has issued: tvx, tvy, tvz, the three d.n products
  // (cycle 1); det', the six cross-product and three tv.n products (cycle 2); det, cx, cy,
  // cz, t'' (cycle 3). The serial list schedule had issued 4 adds and 4 multiplies by then.
  const OpCounts p = op_counts(Kernel::moller, [](const OpGraph& g) { return modulo_schedule(g, full_units(g)); });
  CHECK(p.triangle[0] == FpOps{9, 12, 0, 0});
  CHECK(p.triangle[3] == FpOps{15, 21, 3, 0});  // a full test is the same work either way
  CHECK(p.sphere == op_counts(Kernel::moller).sphere);
}

TEST_CASE("cost: a pipelined unit's buffers are charged at the register file's price per byte", "[cost][pipelined]") {
  const Tech t = load_tech(kDir + "65nm.json");
  Design d = serial_units(2);
  d.units[0].buffer_bytes = 512;  // one register file's worth
  d.units[1].buffer_bytes = 256;
  d.iu.register_files = 0;
  const Cost a = area_mm2(t, d);
  CHECK(*a.of("pipeline_buffers") == Approx(1.5 * 0.0147665));
  CHECK(*a.of("register_files") == 0);
  FrameActivity f;
  f.units.resize(2);
  f.units[1].buffer_access_bytes = 40;  // ten 4-byte registers
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  CHECK(*e.of("pipeline_buffers") == Approx(10 * 7.89613e-12));
}

TEST_CASE("cost: the router's energy is a box test and a register read per bound tested, by hand", "[cost][route]") {
  // 65 nm: fp_add 7.4 pJ, fp_multiply 14.2 pJ, register file 7.89613 pJ. A box test is 6
  // subtractions, 7 multiplies and 6 comparisons (the operation counts above); comparisons run
  // on the adder unless the IU has comparators. Five bounds tested, no other work.
  const Tech t = load_tech(kDir + "65nm.json");
  const Design d = serial_units(1);
  FrameActivity f;
  f.units.resize(1);
  f.router_tests = 5;
  const Cost e = frame_energy_j(t, d, op_counts(Kernel::moller), f);
  const double per_test = 6 * 7.4 + 7 * 14.2 + 6 * 7.4 + 7.89613;  // 196.09613 pJ
  REQUIRE(e.of("router"));
  CHECK(*e.of("router") == Approx(5 * per_test * 1e-12).epsilon(1e-12));
  CHECK(*e.of("router") == Approx(980.48065e-12).epsilon(1e-12));
  // The router's work is its own: none of it shows as the IUs' box tests or register accesses.
  CHECK(*e.of("box_tests") == 0);
  CHECK(*e.of("register_file") == 0);
  // With comparators the 6 comparisons cost 0.54 pJ each.
  Design with_cmp = d;
  with_cmp.iu.comparators = 1;
  CHECK(*frame_energy_j(t, with_cmp, op_counts(Kernel::moller), f).of("router") ==
        Approx(5 * (6 * 7.4 + 7 * 14.2 + 6 * 0.54 + 7.89613) * 1e-12).epsilon(1e-12));
  // Twice the bounds tested, twice the energy; none tested, none charged.
  f.router_tests = 10;
  CHECK(*frame_energy_j(t, d, op_counts(Kernel::moller), f).of("router") == Approx(10 * per_test * 1e-12).epsilon(1e-12));
  f.router_tests = 0;
  CHECK(*frame_energy_j(t, d, op_counts(Kernel::moller), f).of("router") == 0);
}

TEST_CASE("cost: box and node tests read and write the register file as the other operations do", "[cost][bvh]") {
  // One box test (6 adds, 7 multiplies, 6 comparisons: 19 operations) at 65 nm: 3
  // register-file accesses per operation at 7.89613 pJ; node tests likewise, per operation of
  // their graph.
  const Tech t = load_tech(kDir + "65nm.json");
  const Design d = serial_units(1);
  FrameActivity f;
  f.units.resize(1);
  f.units[0].work.box_tests = 1;
  const OpCounts per_op = op_counts(Kernel::moller);
  CHECK(*frame_energy_j(t, d, per_op, f).of("register_file") == Approx(3 * 19 * 7.89613e-12));
  f.units[0].work.box_tests = 0;
  f.units[0].work.node_tests = 2;
  CHECK(*frame_energy_j(t, d, per_op, f).of("register_file") == Approx(3 * 2.0 * per_op.node.total() * 7.89613e-12));
  CHECK(per_op.node.total() > 0);
}
