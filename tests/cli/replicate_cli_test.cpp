// Replicated spheres from the command line (--replicate, issue 27): each ray a sphere would
// receive is handled by exactly one of its copies, the copies' geometry is loaded into each
// copy's memory, `off` is the run without the option, and bad values are refused.
#include "cli_util.h"
#include "ref/image.h"

#include <catch2/catch.hpp>

using namespace oprt::test;

namespace {
const std::string kCommon = " --frames 0:1 --resolution 20x15 --subdivide 2 --ius 6 --balance sa_n --no-progress";
}  // namespace

TEST_CASE("replicate: every ray a sphere receives is handled by one copy and copies are charged", "[cli][replicate]") {
  const fs::path d = temp_dir("replicate_share");
  // Broadcast over flat units: every unit tests each primary ray against every sphere it
  // holds, so a sphere is entered by every primary ray that meets it whichever unit holds it.
  // With copies the primary entries per sphere are the same: one copy, never two, enters for
  // each ray. (A shadow ray stops at a unit's first occluder, which depends on what else the
  // unit holds: its entries may differ.)
  const std::string common = "render " + scene("paper_room.json") + kCommon + " --level analytic --out ";
  REQUIRE(run_oprt(common + (d / "off").string()).status == 0);
  REQUIRE(run_oprt(common + (d / "on").string() + " --replicate auto").status == 0);
  const auto off = stats(d / "off"), on = stats(d / "on");
  CHECK_FALSE(off["frames"][0].contains("replicas"));
  CHECK(on["arch"]["replicate"] == "auto");
  for (int i = 0; i < 2; ++i) {
    const auto& a = off["frames"][i];
    const auto& b = on["frames"][i];
    CHECK(a["image_hash"] == b["image_hash"]);
    REQUIRE(a["sphere_entries"].size() == b["sphere_entries"].size());
    for (std::size_t s = 0; s < a["sphere_entries"].size(); ++s) CHECK(a["sphere_entries"][s][0] == b["sphere_entries"][s][0]);
    REQUIRE(!b["replicas"]["copies"].empty());
    // Per unit, transforms add up to the spheres' entries (each entry on one unit).
    std::uint64_t transforms = 0, entries = 0;
    for (const auto& u : b["ius"])
      for (const char* k : {"primary", "shadow"}) transforms += u["work"][k]["transforms"].get<std::uint64_t>();
    for (const auto& s : b["sphere_entries"])
      for (const auto& k : s) entries += k.get<std::uint64_t>();
    CHECK(transforms == entries);
    // The copies' bytes: each copy beyond the first is its sphere's geometry once more, in
    // the memory of the unit that holds it.
    std::uint64_t held = 0, once = 0;
    for (const auto& u : b["ius"]) held += u["memory"]["assigned_bytes"].get<std::uint64_t>();
    for (const auto& u : a["ius"]) once += u["memory"]["assigned_bytes"].get<std::uint64_t>();
    CHECK(held == once + b["replicas"]["bytes"].get<std::uint64_t>());
    CHECK(b["replicas"]["geometry_bytes"] == once);  // the scene's geometry: each sphere once
    CHECK(b["replicas"]["bytes"].get<std::uint64_t>() > 0);
  }
}

TEST_CASE("replicate: off is the run without the option, byte for byte in stats", "[cli][replicate]") {
  const fs::path d = temp_dir("replicate_off");
  const std::string common = "render " + scene("paper_room.json") + kCommon + " --level analytic --out ";
  REQUIRE(run_oprt(common + (d / "none").string()).status == 0);
  REQUIRE(run_oprt(common + (d / "off").string() + " --replicate off").status == 0);
  REQUIRE(run_oprt(common + (d / "one").string() + " --replicate 1").status == 0);
  auto strip = [](nlohmann::json j) {  // what the host's speed decides
    for (auto& f : j["frames"]) {
      f.erase("wall_s");
      f.erase("rays_per_wall_s");
    }
    j.erase("summary");
    return j;
  };
  CHECK(strip(stats(d / "none")) == strip(stats(d / "off")));
  CHECK(strip(stats(d / "none")) == strip(stats(d / "one")));
}

TEST_CASE("replicate: bad values are refused with the option named", "[cli][replicate]") {
  const fs::path d = temp_dir("replicate_bad");
  for (const char* bad : {"0", "-2", "many", "2.5", "70000"}) {
    INFO(bad);
    const Result r = run_oprt("render " + scene("paper_room.json") + kCommon + " --replicate " + bad + " --out " +
                              (d / "x").string());
    CHECK(r.status == 2);
    CHECK(r.output.find("--replicate") != std::string::npos);
  }
  const fs::path arch = d / "arch.json";
  std::ofstream(arch) << R"({"format": "oprt-arch/1", "balance": {"policy": "sa_n", "replicate": "lots"}})";
  const Result r = run_oprt("render " + scene("paper_room.json") + " --frames 0 --resolution 8x8 --arch " + arch.string() +
                            " --no-progress --out " + (d / "y").string());
  CHECK(r.status == 2);
  CHECK(r.output.find("replicate") != std::string::npos);
}
