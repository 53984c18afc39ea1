// Every input the fuzzers (or a probe) found to crash, hang or exhaust memory, checked in
// under tests/fuzz/regressions/TARGET/ with the loader's extension, loaded the way its fuzz
// target loads it. Beside each input, NAME.expect holds a piece of the error message it
// must now produce (or "ok": it must load and render).
#include "fuzz_scene.h"
#include "fuzz_tech.h"
#include "arch/arch.h"
#include "cost/tech.h"
#include "scene/aff.h"
#include "base/error.h"
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace fs = std::filesystem;
using namespace oprt;

namespace {
using Loader = std::function<void(const std::string&)>;

int replay(const std::string& target, const Loader& load) {
  const fs::path dir = fs::path(OPRT_SOURCE_DIR) / "tests/fuzz/regressions" / target;
  int inputs = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const fs::path in = e.path();
    if (in.extension() == ".expect") continue;
    ++inputs;
    INFO(in.string());
    std::ifstream ex(in.string() + ".expect");
    std::string expect;
    REQUIRE(std::getline(ex, expect));
    if (expect == "ok") {
      CHECK_NOTHROW(load(in.string()));
      continue;
    }
    try {
      load(in.string());
      FAIL("loaded without an error; expected: " << expect);
    } catch (const InputError& err) {
      CHECK_THAT(err.what(), Catch::Contains(expect));
    }
  }
  return inputs;
}
}  // namespace

TEST_CASE("fuzz regressions: oprt-scene/1 JSON", "[fuzz]") {
  const SceneLimits real = scene_limits;
  scene_limits.triangles = fuzz::kTriangleLimit;  // as the fuzz target has it
  CHECK(replay("scene_json", [](const std::string& p) { fuzz::exercise(load_oprt_json(p)); }) >= 8);
  scene_limits = real;
}

TEST_CASE("fuzz regressions: OBJ", "[fuzz]") {
  CHECK(replay("obj", [](const std::string& p) { load_obj(p); }) >= 1);
}

TEST_CASE("fuzz regressions: BART .aff", "[fuzz]") {
  CHECK(replay("aff", [](const std::string& p) { fuzz::exercise(load_aff(p)); }) >= 1);
}

TEST_CASE("fuzz regressions: glTF", "[fuzz]") {
  CHECK(replay("gltf", [](const std::string& p) { fuzz::exercise(load_gltf(p)); }) >= 4);
}

TEST_CASE("fuzz regressions: architecture file", "[fuzz]") {
  CHECK(replay("arch", [](const std::string& p) { (void)to_json(load_arch(p)).dump(); }) >= 1);
}

TEST_CASE("fuzz regressions: technology table", "[fuzz]") {
  CHECK(replay("tech", [](const std::string& p) { fuzz::exercise(load_tech(p)); }) >= 4);
}

TEST_CASE("fuzz regressions: a pipe given as a scene is refused, not read", "[fuzz]") {
  const fs::path d = fs::temp_directory_path() / "oprt_fuzz_pipe";
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string pipe = (d / "scene.json").string();
  REQUIRE(std::system(("mkfifo " + pipe).c_str()) == 0);
  CHECK_THROWS_WITH(load_scene(pipe), Catch::Contains("is not a regular file"));
  CHECK_THROWS_WITH(load_arch(pipe), Catch::Contains("is not a regular file"));
}
