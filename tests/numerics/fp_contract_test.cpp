// The build compiles the kernels with -ffp-contract=off: a fused multiply-add rounds once
// where the source rounds twice, which would change the kernels' bits (reference against
// model) and break the watertight test's exact negation of shared edge functions.
//
// The probe: with x = 1 + 2^-12, fl(x x) = 1 + 2^-11 (the 2^-24 is a tie, rounded to even),
// so x x - (1 + 2^-11) is 0 when rounded as written and 2^-24 when fused.
#include "geom/affine.h"
#include "geom/watertight.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

namespace oprt::fp_control {
float dot_xy_contractible(float ax, float ay, float bx, float by);
bool fma_available();
}  // namespace oprt::fp_control

using namespace oprt;

namespace {
// Loads the compiler cannot see through, so nothing is folded at compile time.
volatile float g_x = 1 + 0x1p-12f, g_y = 1 + 0x1p-11f, g_one = 1;
}  // namespace

TEST_CASE("fp contraction: the probe is sensitive (fused, it gives 2^-24)", "[numerics][fp]") {
  const float x = g_x, y = g_y;
  CHECK(std::fma(x, x, -y) == 0x1p-24f);  // what a fused kernel would compute
  if (!fp_control::fma_available()) {
    WARN("no FMA instructions in this build: the control cannot fuse");
    return;
  }
  // Given the chance (-ffp-contract=fast), the compiler does fuse this expression.
  CHECK(fp_control::dot_xy_contractible(x, y, x, -g_one) == 0x1p-24f);
}

TEST_CASE("fp contraction: the kernels' arithmetic rounds as written", "[numerics][fp]") {
  const float x = g_x, y = g_y, one = g_one;
  // dot3 (Moller's det, u, v, t; the sphere test).
  CHECK(dot3(Vec3f(x, y, 0), Vec3f(x, -one, 0)) == 0.0f);
  // The ray transform (geom/affine.h): x x + (-(1 + 2^-11)) 1 + 0 z + 0.
  Affine<float> m;
  m.m[0][0] = x;
  m.m[0][1] = -y;
  m.m[0][2] = 0;
  CHECK(m.point(Vec3f(x, one, 0)).x == 0.0f);
  CHECK(m.vector(Vec3f(x, one, 0)).x == 0.0f);
  // The watertight edge function a b - c d: x x - 1 1 is 2^-11 rounded as written, 2^-11 +
  // 2^-24 fused.
  int s = 0;
  CHECK(detail::edge(x, x, one, one, &s) == 0x1p-11f);
  // Moller-Trumbore end to end: det = -d.n with d = (x, -1, 0), n = (x, y, 0) is exactly
  // 0 as written, so the ray counts as parallel and exits at the first stage.
  const MollerTriangle<float> tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {x, y, 0}};
  CHECK(intersect_moller(Ray<float>{{0, 0, 1}, {x, -one, 0}, kInf<float>}, tri).stage == TriStage::det);
}

TEST_CASE("fp contraction: every translation unit of the build has -ffp-contract=off", "[numerics][fp]") {
  std::ifstream in(std::string(OPRT_BINARY_DIR) + "/compile_commands.json");
  REQUIRE(in);
  const auto db = nlohmann::json::parse(in);
  int checked = 0;
  for (const auto& entry : db) {
    const std::string file = entry.at("file"), cmd = entry.contains("command") ? entry.at("command").get<std::string>() : "";
    if (file.find(std::string(OPRT_SOURCE_DIR)) != 0) continue;
    INFO(file);
    CHECK(cmd.find("-ffast-math") == std::string::npos);
    if (file.find("fp_contract_control.cpp") != std::string::npos) {
      CHECK(cmd.find("-ffp-contract=fast") != std::string::npos);
      continue;
    }
    const auto off = cmd.rfind("-ffp-contract=off"), fast = cmd.rfind("-ffp-contract=fast");
    CHECK(off != std::string::npos);
    CHECK((fast == std::string::npos || fast < off));  // the last one given wins
    ++checked;
  }
  CHECK(checked > 50);  // model, testbench and tests
}
