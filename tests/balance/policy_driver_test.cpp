// The policy driver (balance/policy_driver.h) on what a frame measured (timing/measured_frame.h).
#include "balance/policy_driver.h"
#include "ref/balance_inputs.h"
#include "scene/load.h"
#include "timing/measured_frame.h"

#include <catch2/catch.hpp>

#include <string>

using namespace oprt;

TEST_CASE("feedback: a sphere's weight is the last frame's cycles of both ray kinds", "[balance][feedback]") {
  // The room's spheres on two units, feedback balance. Last frame's work, by hand: sphere 0
  // did 100 sphere tests for primary rays (900 cycles at 9 each); sphere 1 did 90 for primary
  // rays and 30 for shadow rays (1080 cycles); the others nothing. The greedy assignment puts
  // the heaviest, sphere 1, on a unit and every other sphere (sphere 0 next, then the
  // weightless ones, each on the less loaded unit) on the other. Counting primary rays only,
  // sphere 0 (900) would be the heaviest and alone instead.
  const Scene scene = load_scene(std::string(OPRT_SOURCE_DIR) + "/scenes/paper_room.json");
  const auto spheres = make_spheres(scene, 1);
  const SceneGeometry<float> g = build_geometry<float>(scene, spheres);
  REQUIRE(g.sphere_count() > 3);
  Arch arch;
  arch.balance = "feedback";
  arch.ius = 2;
  REQUIRE(arch.costs.sphere == 9);
  PolicyDriver driver(scene, policy_inputs(scene, g, arch), arch, assign_round_robin(g.sphere_count(), 2), 8, 8);
  timing::FrameRun previous;
  for (auto& kind : previous.per_sphere) kind.assign(g.sphere_count(), WorkCounts{});
  previous.per_sphere[static_cast<int>(RayKind::primary)][0].sphere_tests = 100;
  previous.per_sphere[static_cast<int>(RayKind::primary)][1].sphere_tests = 90;
  previous.per_sphere[static_cast<int>(RayKind::shadow)][1].sphere_tests = 30;
  const MeasuredFrame measured = timing::measured_frame(previous, arch);
  const Assignment a = driver.for_frame(1, &measured);
  REQUIRE(a.units() == 2);
  CHECK(a.is_partition(g.sphere_count()));
  const auto unit = a.unit_of(g.sphere_count());
  CHECK(a.unit[unit[1]] == std::vector<std::uint32_t>{1});
  CHECK(a.unit[unit[0]].size() == g.sphere_count() - 1);
}
