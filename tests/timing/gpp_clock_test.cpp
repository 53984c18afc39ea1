// The GPP's clock interface (timing/gpp_clock.h): a type with all six members is a clock, a
// type missing any one of them, or taking other arguments, is not. (The two clocks assert
// that they are one next to their classes: hw/gpp.h, analytic/gpp.h.)
#include "timing/gpp_clock.h"

#include <catch2/catch.hpp>

#include <string>

using namespace oprt;
using namespace oprt::timing;

namespace {
// One member each, as the recipe calls them.
struct Compute {
  void compute(GppPhase, std::uint64_t) {}
};
struct Load {
  void load(const MemoryLoad&) {}
};
struct WriteConfig {
  void write_config(std::uint32_t, std::uint64_t) {}
};
struct Generated {
  void generated(std::uint32_t) {}
};
struct RoutedNowhere {
  void routed_nowhere(std::uint32_t) {}
};
struct WriteRays {
  template <typename Wave>
  void write_rays(std::uint32_t, const Wave&, const RayWrites&) {}
};

struct AllSix : Compute, Load, WriteConfig, Generated, RoutedNowhere, WriteRays {};
struct NoCompute : Load, WriteConfig, Generated, RoutedNowhere, WriteRays {};
struct NoLoad : Compute, WriteConfig, Generated, RoutedNowhere, WriteRays {};
struct NoWriteConfig : Compute, Load, Generated, RoutedNowhere, WriteRays {};
struct NoGenerated : Compute, Load, WriteConfig, RoutedNowhere, WriteRays {};
struct NoRoutedNowhere : Compute, Load, WriteConfig, Generated, WriteRays {};
struct NoWriteRays : Compute, Load, WriteConfig, Generated, RoutedNowhere {};
// All six names, but write_config takes a name instead of a unit and a byte count.
struct ConfigByName : Compute, Load, Generated, RoutedNowhere, WriteRays {
  void write_config(const std::string&) {}
};
}  // namespace

TEST_CASE("gpp clock: a type with the six members is a clock, one missing any of them is not", "[timing][clock]") {
  STATIC_REQUIRE(is_gpp_clock_v<AllSix>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoCompute>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoLoad>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoWriteConfig>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoGenerated>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoRoutedNowhere>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<NoWriteRays>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<ConfigByName>);
  STATIC_REQUIRE_FALSE(is_gpp_clock_v<int>);
}
