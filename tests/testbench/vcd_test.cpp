// The VCD trace: parses, declares one state signal and one FIFO occupancy per unit, uses
// only the declared state codes, and its timestamps increase.
#include "harness.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace oprt;

TEST_CASE("the VCD parses and holds one state signal per unit", "[vcd]") {
  const Scene scene = load_scene(test::scene_path("paper_room.json"));
  Arch arch;
  arch.ius = 4;
  const std::string path = (std::filesystem::temp_directory_path() / "oprt_vcd_test.vcd").string();
  std::filesystem::remove(path);
  test::simulate_scene<float>(scene, arch, {0, 0}, 16, 16, path);
  std::ifstream in(path);
  REQUIRE(in);
  std::string line;
  std::vector<std::string> scope;  // open $scope names
  auto scope_name = [&] {
    std::string n;
    for (const auto& p : scope) n += (n.empty() ? "" : ".") + p;
    return n;
  };
  std::map<std::string, std::string> code_of;  // "scope.name" -> code
  bool defs_done = false, timescale = false;
  std::uint64_t last_time = 0;
  int times = 0, state_changes = 0;
  while (std::getline(in, line)) {
    if (!defs_done) {
      std::istringstream w(line);
      std::string tok;
      w >> tok;
      if (tok == "$timescale") timescale = line.find("1ps") != std::string::npos;
      if (tok == "$scope") {
        std::string kind, name;
        w >> kind >> name;
        scope.push_back(name);
      }
      if (tok == "$upscope") {
        REQUIRE_FALSE(scope.empty());
        scope.pop_back();
      }
      if (tok == "$var") {
        std::string type, width, code, name;
        w >> type >> width >> code >> name;
        code_of[scope_name() + "." + name] = code;
      }
      if (tok == "$enddefinitions") defs_done = true;
      continue;
    }
    if (line.empty()) continue;
    if (line[0] == '#') {
      const std::uint64_t t = std::stoull(line.substr(1));
      if (times++) CHECK(t > last_time);
      last_time = t;
      continue;
    }
    if (line[0] == 'b') {
      const auto sp = line.find(' ');
      const std::string code = line.substr(sp + 1);
      for (int u = 0; u < 4; ++u)
        if (code == code_of["testbench.engine.iu" + std::to_string(u) + ".state"]) {
          ++state_changes;
          CHECK(std::stoull(line.substr(1, sp - 1), nullptr, 2) <= 5);  // idle .. stall, box (hw/intersection_unit.h)
        }
    }
  }
  CHECK(defs_done);
  CHECK(scope.empty());  // every $scope closed
  CHECK(timescale);
  for (int u = 0; u < 4; ++u) {
    CHECK(code_of.count("testbench.engine.iu" + std::to_string(u) + ".state") == 1);
    CHECK(code_of.count("testbench.engine.fifo" + std::to_string(u) + ".occupancy") == 1);
  }
  CHECK(code_of.count("testbench.engine.bus.busy") == 1);
  CHECK(code_of.count("testbench.engine.gpp.rays_in_flight") == 1);
  CHECK(code_of.count("testbench.engine.gpp.frame") == 1);
  CHECK(state_changes > 100);
}
