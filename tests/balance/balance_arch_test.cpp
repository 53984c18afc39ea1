// The architecture file's "balance": a policy's name, or {"policy", "locality"}.
#include "arch/arch.h"
#include "base/error.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
Arch parse(const std::string& text) { return arch_from_json(nlohmann::json::parse(text), "arch.json"); }
}  // namespace

TEST_CASE("arch: balance as a name or as an object with a locality", "[arch][balance][spatial]") {
  const Arch named = parse(R"({"format": "oprt-arch/1", "balance": "sa_n"})");
  CHECK(named.balance == "sa_n");
  CHECK_FALSE(named.locality);
  CHECK_FALSE(to_json(named).contains("locality"));  // the other policies' records as before

  const Arch spatial = parse(R"({"format": "oprt-arch/1", "balance": "spatial"})");
  CHECK_FALSE(spatial.locality);
  CHECK(to_json(spatial)["locality"] == 0.5);  // its default, recorded as used
  CHECK(to_json(spatial)["balance"] == "spatial");

  const Arch object = parse(R"({"format": "oprt-arch/1", "balance": {"policy": "feedback", "locality": 0.25}})");
  CHECK(object.balance == "feedback");
  CHECK(object.locality == 0.25);
  CHECK(to_json(object)["locality"] == 0.25);
  CHECK_NOTHROW(check_arch(object));

  const Arch knob = parse(R"({"format": "oprt-arch/1", "balance": {"locality": 1}})");
  CHECK(knob.balance == "paper");  // the policy's default: a flag must name one that takes it
  CHECK(knob.locality == 1.0);
  CHECK_THROWS_AS(check_arch(knob), InputError);
  CHECK_FALSE(to_json(parse(R"({"format": "oprt-arch/1", "balance": "feedback"})")).contains("locality"));

  for (const char* bad : {R"({"policy": "spatial", "locality": -0.1})", R"({"policy": "spatial", "locality": 1.01})",
                          R"({"policy": "spatial", "locality": "half"})", R"({"policy": "spatial", "extra": 1})",
                          R"({"policy": "sideways"})", R"(["spatial"])"}) {
    INFO(bad);
    try {
      parse(std::string(R"({"format": "oprt-arch/1", "balance": )") + bad + "}");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.file() == "arch.json");
      CHECK(e.place().rfind("/balance", 0) == 0);
    }
  }
  try {
    Arch a = parse(R"({"format": "oprt-arch/1", "balance": {"policy": "view", "locality": 0.5}})");
    check_arch(a);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.file() == "arch.json");
    CHECK(e.place() == "balance.locality with balance view");
  }
}
