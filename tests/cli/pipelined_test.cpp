// The pipelined intersection unit (`--iu pipelined`) as a user runs it: the same images as
// the reference under both IU models and at every level, its stages' cycles adding up, its
// timing the same whether it runs ahead or waits out every ray, and area and energy in the
// statistics.
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

#include <fstream>

using namespace oprt::test;

namespace {
std::string write_arch(const fs::path& d, const std::string& name, const std::string& json) {
  const fs::path f = d / (name + ".json");
  std::ofstream(f) << json;
  return f.string();
}
}  // namespace

TEST_CASE("cli: both IU models render the reference image at at and lt; pipelined takes far fewer cycles",
          "[cli][pipelined]") {
  const fs::path d = temp_dir("pipelined_images");
  for (const char* name : {"paper_polygons.json", "paper_room.json"}) {
    INFO(name);
    const std::string frames = " --frames 3 --resolution 32x24";
    REQUIRE(run_oprt("reference " + scene(name) + frames + " --out " + (d / "ref").string()).status == 0);
    const auto reference = oprt::read_exr((d / "ref" / "frame_0003.exr").string());
    std::uint64_t makespan[2] = {};
    int m = 0;
    for (const char* iu : {"serial", "pipelined"}) {
      for (const char* level : {"at", "lt"}) {
        INFO(iu << " at level " << level);
        const fs::path out = d / (std::string(iu) + level);
        REQUIRE(run_oprt("render " + scene(name) + frames + " --ius 8 --no-progress --iu " + iu + " --level " + level +
                         " --out " + out.string())
                    .status == 0);
        CHECK(oprt::read_exr((out / "frame_0003.exr").string()) == reference);
        if (std::string(level) == "at") makespan[m] = stats(out)["frames"][0]["makespan_cycles"];
      }
      ++m;
    }
    // Brute force inside the spheres: the triangle unit's one test per cycle against the
    // serial unit's 4 to 22 cycles per test.
    CHECK(makespan[1] * 2 < makespan[0]);
  }
}

TEST_CASE("cli: pipelined units running ahead report exactly what units waiting out every ray report",
          "[cli][pipelined][ahead]") {
  const fs::path d = temp_dir("pipelined_ahead");
  // Few rays in flight and short queues, so that queues fill, units freeze and rays wait
  // for slots; memory latency so that the triangle unit waits for data.
  const std::string body = R"("format": "oprt-arch/1", "ius": 6,
      "memory": {"model": "latency", "latency_cycles": 20, "bytes_per_cycle": 16},
      "gpp": {"cycles_per_ray": 3, "cycles_per_hit": 40},
      "iu": {"model": "pipelined", "queue_depth": 2, "rays_in_flight": 3})";
  for (const std::string mode : {"ahead", "sync"}) {
    const std::string arch =
        write_arch(d, mode, "{" + body + (mode == "sync" ? ", \"sync_every_ray\": true" : "") + "}");
    REQUIRE(run_oprt("render " + scene("paper_room.json") + " --arch " + arch +
                     " --frames 0:1 --resolution 40x40 --no-progress --vcd " + (d / mode / "trace.vcd").string() +
                     " --out " + (d / mode).string())
                .status == 0);
  }
  nlohmann::json a = without_wall_clock(stats(d / "ahead")), s = without_wall_clock(stats(d / "sync"));
  a.erase("arch");
  s.erase("arch");
  CHECK(a == s);
  CHECK(bytes_of(d / "ahead" / "trace.vcd") == bytes_of(d / "sync" / "trace.vcd"));
  // The FIFO's peak occupancy is taken in time order: with units running ahead the queue's
  // length in simulation order would differ. It is the same as waiting out every ray, and
  // a real peak (the GPP writes rays faster than a unit takes them).
  const auto& u = a["frames"][0]["ius"][0];
  CHECK(u["fifo"]["peak"].get<int>() > 3);
  CHECK(u["fifo"]["pushes"] == u["fifo"]["pops"]);
  CHECK(u["pipeline"]["stages"]["sphere"]["stall_queue_full"].get<int>() > 0);
  CHECK(u["pipeline"]["stages"]["triangle"]["stall_memory"].get<int>() > 0);
}

TEST_CASE("cli: analytic times pipelined units exactly as at under the ideal architecture", "[cli][pipelined][analytic]") {
  const fs::path d = temp_dir("pipelined_analytic");
  const std::string arch = write_arch(d, "arch", R"({"format": "oprt-arch/1", "ius": 9,
      "iu": {"model": "pipelined", "queue_depth": 1, "rays_in_flight": 2, "triangle": {"adders": 6, "multipliers": 7}}})");
  const std::string common = "render " + scene("paper_room.json") + " --arch " + arch + " --frames 7 --resolution 28x28 --no-progress";
  REQUIRE(run_oprt(common + " --level at --out " + (d / "at").string()).status == 0);
  REQUIRE(run_oprt(common + " --level analytic --out " + (d / "an").string()).status == 0);
  const auto a = stats(d / "at")["frames"][0], b = stats(d / "an")["frames"][0];
  CHECK(a["makespan_cycles"] == b["makespan_cycles"]);
  for (int u = 0; u < 9; ++u) {
    CHECK(a["ius"][u]["cycles"] == b["ius"][u]["cycles"]);
    CHECK(a["ius"][u]["pipeline"] == b["ius"][u]["pipeline"]);
    CHECK(a["ius"][u]["fifo"] == b["ius"][u]["fifo"]);
  }
  CHECK(a["energy_j"] == b["energy_j"]);
  // 18 adder ops on 6 adders, 21 multiplies on 7 multipliers: a triangle every 3 cycles.
  CHECK(stats(d / "at")["iu_stages"]["triangle"]["ii"] == 3);
  CHECK(a["ius"][0]["pipeline"]["stages"]["triangle"]["busy"] == 3 * a["ius"][0]["pipeline"]["triangle_tests"].get<int>());
}

TEST_CASE("cli: a pipelined unit's stages add up to the makespan, and area and energy come with their components",
          "[cli][pipelined][cost]") {
  const fs::path d = temp_dir("pipelined_stats");
  const std::string arch = write_arch(d, "arch", R"({"format": "oprt-arch/1", "ius": 4, "ray_fifo_depth": 8,
      "bus": {"model": "shared"}, "iu": {"model": "pipelined", "queue_depth": 2}})");
  REQUIRE(run_oprt("render " + scene("paper_polygons.json") + " --arch " + arch +
                   " --frames 0 --resolution 24x24 --no-progress --out " + d.string())
              .status == 0);
  const auto s = stats(d);
  const auto& f = s["frames"][0];
  const std::uint64_t makespan = f["makespan_cycles"];
  std::uint64_t rays = f["rays"]["primary"].get<std::uint64_t>() + f["rays"]["shadow"].get<std::uint64_t>();
  double busy = 0;
  for (const auto& u : f["ius"]) {
    const auto& p = u["pipeline"];
    for (const char* stage : {"sphere", "transform", "triangle"}) {
      INFO(stage);
      const auto& st = p["stages"][stage];
      std::uint64_t sum = st["busy"].get<std::uint64_t>() + st["stall_queue_full"].get<std::uint64_t>() +
                          st["stall_queue_empty"].get<std::uint64_t>() + st["idle"].get<std::uint64_t>();
      if (st.contains("stall_memory")) sum += st["stall_memory"].get<std::uint64_t>();
      CHECK(sum == makespan);
    }
    // The unit's busy cycles are those in which it held a ray; idle the rest.
    CHECK(u["busy_cycles"] == p["occupied_cycles"]);
    CHECK(u["cycles"]["idle"].get<std::uint64_t>() + p["occupied_cycles"].get<std::uint64_t>() == makespan);
    // Every ray passes through every unit's FIFO: one push and one pop each.
    CHECK(u["fifo"]["pushes"] == rays);
    CHECK(u["fifo"]["pops"] == rays);
    CHECK(u["fifo"]["peak"].get<int>() <= 8);
    // The sphere unit issues every sphere test it made (II 1).
    CHECK(p["stages"]["sphere"]["busy"] == u["work"]["primary"]["sphere_tests"].get<std::uint64_t>() +
                                               u["work"]["shadow"]["sphere_tests"].get<std::uint64_t>());
    CHECK(p["answer_wait_cycles"].get<int>() > 0);  // a shared bus
    busy += u["busy_cycles"].get<double>();
  }
  CHECK(f["parallel_efficiency"].get<double>() == Approx(busy / (4.0 * makespan)));

  // Area once per run, energy per frame, each a total of its components (a component the
  // table cannot price is null and left out).
  const auto total = [](const nlohmann::json& c) {
    double t = 0;
    for (const auto& [k, v] : c.items())
      if (k != "total" && !v.is_null()) t += v.get<double>();
    return t;
  };
  REQUIRE(s.contains("area_mm2"));
  CHECK(s["area_mm2"]["total"].get<double>() == Approx(total(s["area_mm2"])));
  for (const char* k : {"fp_adders", "fp_multipliers", "object_memories", "ray_fifos", "pipeline_buffers"})
    CHECK(s["area_mm2"][k].get<double>() > 0);
  // 4 units of 12 + 15 + 18 adders (II 1 for each stage's graph).
  CHECK(s["area_mm2"]["fp_adders"].get<double>() == Approx(4 * 45 * 3311e-6));
  REQUIRE(f.contains("energy_j"));
  CHECK(f["energy_j"]["total"].get<double>() == Approx(total(f["energy_j"])));
  CHECK(f["energy_j"]["bus"].is_null());  // the 65 nm table has no wire energy
  CHECK(f["frame_time_s"].get<double>() == Approx(makespan * 10e-9));  // 100 MHz
  CHECK(s["tech"]["file"].get<std::string>().find("65nm.json") != std::string::npos);

  // Another table: 45 nm from Horowitz; the CSV carries the totals.
  REQUIRE(run_oprt("render " + scene("paper_polygons.json") + " --arch " + arch + " --tech " + OPRT_SOURCE_DIR +
                   "/testbench/tech/45nm.json --frames 0 --resolution 24x24 --no-progress --out " + (d / "45").string())
              .status == 0);
  const auto s45 = stats(d / "45");
  CHECK(s45["frames"][0]["energy_j"]["total"].get<double>() < f["energy_j"]["total"].get<double>());
  std::ifstream csv(d / "45" / "stats.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  CHECK(header.find(",frame_time_s,energy_j,area_mm2") != std::string::npos);
  CHECK(row.substr(row.rfind(',') + 1) != "");
}

TEST_CASE("cli: bad IU and technology options end with a clear message and exit status 2", "[cli][pipelined]") {
  const fs::path d = temp_dir("pipelined_bad");
  Result r = run_oprt("render " + scene("paper_room.json") + " --iu superscalar");
  CHECK(r.status == 2);
  r = run_oprt("render " + scene("paper_room.json") + " --iu pipelined --accel bvh --out " + d.string());
  CHECK(r.status == 2);
  CHECK(r.output.find("brute force") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --iu pipelined --top bvh --out " + d.string());
  CHECK(r.status == 2);
  CHECK(r.output.find("--iu pipelined with --top bvh") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --iu pipelined --sram 16K --out " + d.string());
  CHECK(r.status == 2);
  CHECK(r.output.find("--iu pipelined with --sram 16K") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --arch " +
               write_arch(d, "q", R"({"format": "oprt-arch/1", "iu": {"model": "pipelined", "rays_in_flight": 0}})"));
  CHECK(r.status == 2);
  CHECK(r.output.find("/iu/rays_in_flight") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --arch " +
               write_arch(d, "k", R"({"format": "oprt-arch/1", "iu": {"model": "pipelined", "triangle": {"dividers": 1}}})"));
  CHECK(r.status == 2);
  CHECK(r.output.find("dividers") != std::string::npos);
  r = run_oprt("render " + scene("paper_room.json") + " --tech " + (d / "none.json").string() + " --out " +
               (d / "out").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("none.json") != std::string::npos);
  CHECK_FALSE(fs::exists(d / "out" / "stats.json"));
}

TEST_CASE("cli: a pipelined unit's stages are the `stage` signal group of its unit", "[cli][pipelined][trace]") {
  const fs::path d = temp_dir("pipelined_stage_signals");
  REQUIRE(run_oprt("render " + scene("paper_room.json") +
                   " --iu pipelined --ius 4 --frames 0 --resolution 16x16 --no-progress --trace-units 1 --trace-signals stage"
                   " --vcd " + (d / "t.vcd").string() + " --out " + d.string())
              .status == 0);
  const std::string vcd = bytes_of(d / "t.vcd");
  // Unit 1's sphere, transform and triangle units, its two queues and its rays in flight;
  // nothing of another unit, nor another group.
  std::size_t vars = 0;
  for (std::size_t at = vcd.find("$var "); at != std::string::npos; at = vcd.find("$var ", at + 1)) ++vars;
  CHECK(vars == 6);
  for (const char* name : {" sphere $end", " transform $end", " triangle $end", " transform_queue $end",
                           " triangle_queue $end", " rays_in_flight $end"})
    CHECK(vcd.find(name) != std::string::npos);
  CHECK(vcd.find("$scope module iu1 $end") != std::string::npos);
  CHECK(vcd.find("$scope module iu0 $end") == std::string::npos);
  CHECK(vcd.find(" occupancy $end") == std::string::npos);
}
