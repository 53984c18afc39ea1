// The one parser of each kind of number (base/numbers.h): at each limit, one past it, and far
// past it; every refusal states the real limit.
#include "base/error.h"
#include "base/json_in.h"
#include "base/numbers.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <string>

using namespace oprt;

namespace {
const NumberSource at{"--x", "v"};
constexpr std::uint64_t kMax = ~std::uint64_t{0};

template <typename F>
void refused(F f, const std::string& says) {
  try {
    f();
    FAIL("accepted; expected: " << says);
  } catch (const InputError& e) {
    CHECK(e.file() == "--x");
    CHECK_THAT(e.problem(), Catch::Contains(says));
  }
}
}  // namespace

TEST_CASE("numbers: counts take every value in their range, and state it when refusing", "[numbers]") {
  CHECK(parse_count("65536", 1, 65536, at) == 65536);
  CHECK(parse_count("1", 1, 65536, at) == 1);
  CHECK(parse_count(" 42 ", 0, 100, at) == 42);
  refused([] { parse_count("65537", 1, 65536, at); }, "value 65537 is out of range [1, 65536]");
  refused([] { parse_count("0", 1, 65536, at); }, "value 0 is out of range [1, 65536]");
  refused([] { parse_count("99999999999999999999999999", 1, 65536, at); }, "out of range [1, 65536]");
  // The whole of 64 bits, and one past it.
  CHECK(parse_count("18446744073709551615", 0, kMax, at) == kMax);
  refused([] { parse_count("18446744073709551616", 0, kMax, at); }, "out of range [0, 18446744073709551615]");
  // Frame numbers beyond 9 digits (the old parser's limit) are numbers too.
  CHECK(parse_count("2147483647", 0, 2147483647, at) == 2147483647);
  refused([] { parse_count("2147483648", 0, 2147483647, at); }, "out of range [0, 2147483647]");
  for (const char* bad : {"", "-1", "+3", "1e3", "0x10", "3.0", "4K", "abc"})
    refused([bad] { parse_count(bad, 0, 100, at); }, "expected a whole number in [0, 100]");
}

TEST_CASE("numbers: byte counts take K, M, G, T and KiB-style suffixes up to the stated limit", "[numbers]") {
  const std::uint64_t tib = std::uint64_t{1} << 40;
  CHECK(parse_bytes("65536", tib, at) == 65536);
  CHECK(parse_bytes("64K", tib, at) == 65536);
  CHECK(parse_bytes("64k", tib, at) == 65536);
  CHECK(parse_bytes("64KB", tib, at) == 65536);
  CHECK(parse_bytes("64 KiB", tib, at) == 65536);
  CHECK(parse_bytes("4M", tib, at) == 4194304);
  CHECK(parse_bytes("1G", tib, at) == 1073741824);
  CHECK(parse_bytes("1073741824", tib, at) == 1073741824);
  CHECK(parse_bytes("1.5G", tib, at) == 1610612736);
  CHECK(parse_bytes("0", tib, at) == 0);
  // At the limit, one byte past it, and far past it.
  CHECK(parse_bytes("1T", tib, at) == tib);
  CHECK(parse_bytes("1099511627776", tib, at) == tib);
  CHECK(parse_bytes("1024GiB", tib, at) == tib);
  refused([&] { parse_bytes("1099511627777", tib, at); }, "is more than the limit: at most 1 TiB (1099511627776 bytes)");
  refused([&] { parse_bytes("2T", tib, at); }, "value 2T (2199023255552 bytes) is more than the limit: at most 1 TiB");
  refused([&] { parse_bytes("99999999999T", tib, at); }, "at most 1 TiB");
  refused([&] { parse_bytes("999999999999999999999999", tib, at); }, "at most 1 TiB");
  // The whole of 64 bits.
  CHECK(parse_bytes("18446744073709551615", kMax, at) == kMax);
  CHECK(parse_bytes("16777215T", kMax, at) == (std::uint64_t{16777215} << 40));
  refused([] { parse_bytes("16777216T", kMax, at); }, "more than the limit");
  refused([&] { parse_bytes("1.3K", tib, at); }, "not a whole number of bytes");
  for (const char* bad : {"", "-1", "K", "4X", "4 KiBB", "4kib", "1e3", "0x10", "4P"})
    refused([&] { parse_bytes(bad, tib, at); }, "expected a byte count such as 65536, 64K, 4M or 1.5G");
}

TEST_CASE("numbers: times are exact to the picosecond, up to SystemC's largest", "[numbers]") {
  CHECK(parse_time_ps("10 ns", false, at) == 10000);
  CHECK(parse_time_ps("1us", false, at) == 1000000);
  CHECK(parse_time_ps("2.5ms", false, at) == 2500000000);
  CHECK(parse_time_ps("2e3 us", false, at) == 2000000000);
  CHECK(parse_time_ps("0.001ns", false, at) == 1);
  CHECK(parse_time_ps("0", true, at) == 0);
  // 2^64 - 1 ps is SystemC's largest time: at it, one picosecond past it, and far past it.
  CHECK(parse_time_ps("18446744073709551615ps", false, at) == kMax);
  CHECK(parse_time_ps("18446744.073709551615 s", false, at) == kMax);
  refused([] { parse_time_ps("18446744073709551616ps", false, at); }, "more than 2^64 - 1 ps");
  refused([] { parse_time_ps("1e30 s", false, at); }, "more than 2^64 - 1 ps");
  refused([] { parse_time_ps("0.5ps", false, at); }, "not a whole number of picoseconds");
  refused([] { parse_time_ps("0 ns", false, at); }, "must be positive");
  refused([] { parse_time_ps("10", false, at); }, "a time needs a unit");
  refused([] { parse_time_ps("5parsec", false, at); }, "unknown time unit \"parsec\"");
  refused([] { parse_time_ps("-1us", false, at); }, "expected a time");
  CHECK(format_time_ps(kMax) == "18446744.073709551615s");
}

TEST_CASE("numbers: byte counts in JSON files as numbers or text, and integers out of range", "[numbers]") {
  const auto doc = nlohmann::json::parse(
      R"({"a": 4294967296, "b": "1G", "c": 1099511627777, "d": "2T", "e": 18446744073709551615, "f": -1, "g": 1e20,
          "h": 4096.0, "i": true})");
  const JsonIn j(doc, "f.json");
  const std::uint64_t tib = std::uint64_t{1} << 40;
  CHECK(j.at("a").bytes(tib) == 4294967296);
  CHECK(j.at("b").bytes(tib) == 1073741824);
  CHECK_THROWS_WITH(j.at("c").bytes(tib), Catch::Contains("f.json: /c: value 1099511627777") && Catch::Contains("1 TiB"));
  CHECK_THROWS_WITH(j.at("d").bytes(tib), Catch::Contains("f.json: /d: value 2T") && Catch::Contains("1 TiB"));
  CHECK_THROWS_WITH(j.at("e").bytes(tib), Catch::Contains("1 TiB"));
  CHECK_THROWS_WITH(j.at("f").bytes(tib), Catch::Contains("/f: value -1 is out of range"));
  CHECK_THROWS_WITH(j.at("i").bytes(tib), Catch::Contains("expected a byte count"));
  // Whole numbers written as floats: in range, or out of it like any integer (not "not an integer").
  CHECK(j.at("h").integer(1, 4096) == 4096);
  CHECK_THROWS_WITH(j.at("h").integer(1, 4095), Catch::Contains("value 4096 is out of range [1, 4095]"));
  CHECK_THROWS_WITH(j.at("g").integer(1, 65536), Catch::Contains("value 1e+20 is out of range [1, 65536]"));
  CHECK_THROWS_WITH(j.at("e").integer(0, 65536), Catch::Contains("value 18446744073709551615 is out of range [0, 65536]"));
}
