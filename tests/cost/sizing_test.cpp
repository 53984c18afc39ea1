#include "cost/host_memory.h"
#include "cost/sizing.h"

#include <catch2/catch.hpp>

using namespace oprt;

// Sizes by hand, in single precision: a ray is 8 + 7 x 4 = 36 bytes (id, kind, o, d, tmax),
// its local copy in a pipelined IU's ray store 6 x 4 = 24 bytes.

TEST_CASE("sizing: a unit's object memory, registers and FIFO grow to their peak over the run", "[cost][sizing]") {
  Arch a;
  a.fifo_depth = 4;
  UnitSize z;
  timing::UnitRun r;
  r.fifo_peak = 2;
  r.fifo_pushes = 5;
  grow_unit(z, a, r, UnitHolds{1000, 68});
  CHECK(z.object_memory_bytes == 1000);
  CHECK(z.config_bytes == 68);
  CHECK(z.fifo_bytes == 4 * 36);  // its depth, whatever it held
  CHECK(z.miss_register_bytes == 0);
  CHECK(z.buffer_bytes == 0);
  CHECK(z.stack_bytes == 0);
  grow_unit(z, a, r, UnitHolds{500, 34});  // a smaller frame leaves the peak
  CHECK(z.object_memory_bytes == 1000);
  CHECK(z.config_bytes == 68);
  grow_unit(z, a, r, UnitHolds{1200, 34});
  CHECK(z.object_memory_bytes == 1200);

  // Unbounded: as many entries as it ever held, one if a ray passed through at once, none else.
  a.fifo_depth = 0;
  UnitSize u;
  r.fifo_peak = 0;
  r.fifo_pushes = 0;
  grow_unit(u, a, r, {});
  CHECK(u.fifo_bytes == 0);
  r.fifo_pushes = 3;
  grow_unit(u, a, r, {});
  CHECK(u.fifo_bytes == 36);
  r.fifo_peak = 3;
  grow_unit(u, a, r, {});
  CHECK(u.fifo_bytes == 3 * 36);
  a.precision = "double";  // 8 + 7 x 8 = 64 bytes a ray
  grow_unit(u, a, r, {});
  CHECK(u.fifo_bytes == 3 * 64);
}

TEST_CASE("sizing: a unit that is a cache is memory.sram_bytes, with its miss registers", "[cost][sizing]") {
  Arch a;
  a.memory.sram_bytes = 4096;  // line 64 bytes, 4 misses outstanding by default
  timing::UnitRun r;
  r.cache = true;
  r.memory.misses = 10;
  r.memory.dram_bytes = 640;
  r.memory_load_bytes = 100;
  r.memory_bytes = 5000;
  UnitSize z;
  grow_unit(z, a, r, UnitHolds{10000, 0});
  CHECK(z.object_memory_bytes == 4096);
  CHECK(z.miss_register_bytes == 4 * (8 + 64));  // address and line each
  const UnitActivity act = unit_activity(a, r, UnitHolds{10000, 0});
  CHECK(act.dram_bytes == 640);
  CHECK(act.memory_read_bytes == 5000);
  CHECK(act.memory_write_bytes == 100 + 640);       // loaded, and the lines filled
  CHECK(act.miss_register_access_bytes == 2 * 10 * 64);  // each miss's line written and read
  // Its spheres fit after all: what they need.
  UnitSize small;
  grow_unit(small, a, r, UnitHolds{3000, 0});
  CHECK(small.object_memory_bytes == 3000);
}

TEST_CASE("sizing: a pipelined IU's ray store and traversal stacks, and what a frame did with them", "[cost][sizing]") {
  Arch a;
  a.iu.model = IuModel::pipelined;
  a.accel = "bvh";  // 16 rays in flight, stacks 16 deep by default
  timing::UnitRun r;
  r.rays = 10;
  r.fifo_pushes = r.fifo_pops = 10;
  r.pipeline = timing::PipelineStats{};
  r.pipeline->jobs = 7;
  r.pipeline->stack_pushes = 5;
  r.pipeline->stack_spills = 2;
  r.pipeline->stack_fills = 1;
  r.memory_bytes = 300;
  for (int k = 0; k < kRayKinds; ++k) r.work[k].sphere_tests = 3 + k;  // 3 + 4 + 5 + 6 with four kinds
  r.work[1].node_tests = 2;
  UnitSize z;
  grow_unit(z, a, r, UnitHolds{0, 68});
  CHECK(z.buffer_bytes == 16 * (36 + 24));
  CHECK(z.stack_bytes == 16 * 16 * 4);
  const UnitActivity act = unit_activity(a, r, UnitHolds{0, 68});
  CHECK(act.work.sphere_tests == 3 * kRayKinds + kRayKinds * (kRayKinds - 1) / 2);  // every ray kind's
  CHECK(act.work.node_tests == 2);
  CHECK(act.buffer_access_bytes == 10 * 36 + 7 * (36 + 2 * 24));  // each ray written; per job read, local copy written and read
  CHECK(act.stack_access_bytes == 2 * 5 * 4);
  CHECK(act.memory_write_bytes == 2 * 4);  // a spilled entry
  CHECK(act.memory_read_bytes == 300 + 1 * 4);  // and a filled one
  CHECK(act.fifo_pushes == 10);
  CHECK(act.fifo_pops == 10);
  CHECK(act.config_write_bytes == 68);
  a.accel = "brute";  // no stacks without a tree
  UnitSize brute;
  grow_unit(brute, a, r, {});
  CHECK(brute.stack_bytes == 0);
}

TEST_CASE("sizing: the design's router and IU arithmetic, and the frame's router tests", "[cost][sizing]") {
  Arch a;
  Design serial = initial_design(a, 3, 10);
  CHECK(serial.units.size() == 3);
  CHECK(serial.ray_bytes == 36);
  CHECK(!serial.double_precision);
  CHECK(serial.router_adders == 0);
  CHECK(serial.router_register_bytes == 0);
  CHECK(serial.iu.adders == 1);  // the paper's IU
  CHECK(serial.iu.multipliers == 1);
  CHECK(serial.iu.register_files == 1);
  CHECK(serial.iu.register_accesses_per_op == 3);

  a.route.policy = "multicast";
  a.route.units.adders = 2;
  a.route.units.multipliers = 3;
  a.route.lanes = 8;
  const Design routed = initial_design(a, 3, 10);
  CHECK(routed.router_adders == 2 * 8);
  CHECK(routed.router_multipliers == 3 * 8);
  CHECK(routed.router_register_bytes == 3 * 6 * 4);  // a box per unit
  a.route.bound = "sphere";
  CHECK(initial_design(a, 3, 10).router_register_bytes == 10 * 6 * 4);  // a box per sphere

  timing::FrameFigures f;
  f.rays[0] = 10;
  f.rays[1] = 5;
  f.route.bounds = 8;
  f.bus_bytes = 999;
  const FrameActivity act = frame_activity(a, f, 0.25);
  CHECK(act.router_tests == 15 * 8);
  CHECK(act.bus_bytes == 999);
  CHECK(act.frame_time_s == 0.25);
  CHECK(act.units.empty());
  a.route.policy = "broadcast";
  CHECK(frame_activity(a, f, 0.25).router_tests == 0);

  a.iu.model = IuModel::pipelined;
  a.accel = "bvh";
  const Design p = initial_design(a, 1, 1);
  CHECK(p.iu.register_files == 0);  // operands through pipeline registers
  CHECK(p.iu.register_accesses_per_op == 1);
  CHECK(p.iu.box_adders > 0);  // a box unit of its own
  CHECK(p.iu.node_adders == 0);  // no node unit without --top bvh
}

TEST_CASE("host memory: the estimate's parts, by hand", "[cost][memory]") {
  RunShape r;
  r.level = Level::analytic;
  r.units = 8;
  CHECK(bytes_per_triangle(r) == 160);
  CHECK(bytes_per_vertex(r) == 72);
  r.bvh = true;
  CHECK(bytes_per_triangle(r) == 250);
  r.double_precision = true;
  CHECK(bytes_per_triangle(r) == 300);
  CHECK(bytes_per_vertex(r) == 84);
  r.bvh = r.double_precision = false;

  // 100 pixels x 2 rays at 160 + 8 x 8 bytes, 24 bytes a pixel, beside the process's 32 MiB.
  MemoryEstimate e = memory_estimate(r, 100, 2, {"--resolution", "10x10"});
  REQUIRE(e.parts.size() == 2);
  CHECK(e.parts[1].bytes == 100 * 2 * (160 + 8 * 8) + 100 * 24);
  CHECK(e.parts[1].file == "--resolution");
  CHECK(e.total() == (32ull << 20) + 47200);

  // A cache of 4 KiB keeps a tag (24 bytes) per 64-byte line in each of the 8 units.
  r.sram_bytes = 4096;
  add_geometry(e, r, 500, 1000, "room.json");
  REQUIRE(e.parts.size() == 4);
  CHECK(e.parts[2].bytes == 500 * 72 + 1000 * 160);
  CHECK(e.parts[2].file == "room.json");
  CHECK(e.parts[3].bytes == 4096 / 64 * 24 * 8);

  // The reference: 48 bytes a pixel; estimates saturate instead of wrapping.
  RunShape ref;
  ref.timed = false;
  CHECK(memory_estimate(ref, 1000, 1).parts[1].bytes == 48000);
  CHECK(memory_estimate(r, ~std::uint64_t{0} / 2, 3).total() == ~std::uint64_t{0});
}

TEST_CASE("host memory: a pixel's rays grow by a bounce per depth only where a material reflects or transmits",
          "[cost][memory]") {
  Scene s;
  s.lights.resize(2);
  s.materials.resize(2);
  CHECK(rays_per_pixel(s, -1) == 3);  // primary and two shadow rays: nothing reflects
  CHECK(rays_per_pixel(s, 5) == 3);
  s.materials[1].reflect = Vec3d(0.5);
  CHECK(rays_per_pixel(s, -1) == 3 * 6);  // the scene's default depth, 5
  CHECK(rays_per_pixel(s, 2) == 3 * 3);
  CHECK(rays_per_pixel(s, 0) == 3);
  s.materials[1].reflect = Vec3d(0);
  s.materials[0].transmit = Vec3d(0, 0.2, 0);
  s.depth = 1;
  CHECK(rays_per_pixel(s, -1) == 3 * 2);
}
