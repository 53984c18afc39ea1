// The transaction timeline on hand-made slices: valid JSON in Chrome's trace-event format,
// times in microseconds to the picosecond, clipped to the window, runs of sphere-test-only
// visits joined, filtered tracks absent.
#include "trace/timeline.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace oprt;
namespace fs = std::filesystem;

namespace {
fs::path temp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("oprt_trace_tests_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}
nlohmann::json slices(const fs::path& p) {
  std::ifstream in(p);
  const nlohmann::json doc = nlohmann::json::parse(in);  // throws if not JSON
  nlohmann::json x = nlohmann::json::array();
  for (const auto& e : doc.at("traceEvents"))
    if (e.at("ph") == "X") x.push_back(e);
  return x;
}
}  // namespace

TEST_CASE("timeline: slices in microseconds to the picosecond, with their arguments", "[trace][timeline]") {
  const fs::path p = temp("t.json");
  {
    TimelineWriter t(p.string());
    const int gpp = t.track("top.gpp", "gpp", "GPP");
    const int iu = t.track("top.iu0", "state", "IU 0");
    t.slice(gpp, "issue", 1234567, 1244567, {{"ray", 7}});
    t.slice(iu, "transform", 0, 190000, {{"ray", 8}});
    t.slice(iu, "primitive", 190000, 190000);  // no time: no slice
    t.close();
  }
  const auto x = slices(p);
  REQUIRE(x.size() == 2);
  CHECK(x[0]["name"] == "issue");
  CHECK(x[0]["tid"] == 1);
  CHECK(x[0]["ts"].get<double>() == 1.234567);
  CHECK(x[0]["dur"].get<double>() == 0.01);
  CHECK(x[0]["args"]["ray"] == 7);
  CHECK(x[1]["tid"] == 2);
  CHECK(x[1]["ts"].get<double>() == 0);
  CHECK(x[1]["dur"].get<double>() == 0.19);
}

TEST_CASE("timeline: back-to-back sphere-test visits join into one slice, a gap or other work ends it", "[trace][timeline]") {
  const fs::path p = temp("runs.json");
  {
    TimelineWriter t(p.string());
    const int iu = t.track("top.iu0", "state", "IU 0");
    t.run_slice(iu, "sphere", 0, 90, 1);
    t.run_slice(iu, "sphere", 90, 180, 2);
    t.run_slice(iu, "sphere", 180, 270, 5);
    t.slice(iu, "transform", 270, 460, {{"ray", 6}});
    t.run_slice(iu, "sphere", 500, 590, 7);  // after a gap
    t.close();
  }
  const auto x = slices(p);
  REQUIRE(x.size() == 3);
  CHECK(x[0]["args"] == nlohmann::json{{"first_ray", 1}, {"last_ray", 5}, {"rays", 3}});
  CHECK(x[0]["dur"].get<double>() == 0.00027);
  CHECK(x[1]["name"] == "transform");
  CHECK(x[2]["args"] == nlohmann::json{{"ray", 7}});
}

TEST_CASE("timeline: the window clips slices and the filter removes tracks", "[trace][timeline]") {
  const fs::path p = temp("window.json");
  {
    TimelineWriter t(p.string());
    t.set_filter([](const std::string& scope, const std::string&) { return scope != "top.iu1"; });
    const int a = t.track("top.iu0", "state", "IU 0");
    CHECK(t.track("top.iu1", "state", "IU 1") == TimelineWriter::kNotTraced);
    t.set_window(100, 200);
    t.slice(a, "sphere", 50, 150);
    t.slice(a, "primitive", 150, 250);
    t.slice(a, "stall", 250, 300);
    t.slice(TimelineWriter::kNotTraced, "sphere", 120, 130);
    t.close();
  }
  const auto x = slices(p);
  REQUIRE(x.size() == 2);
  CHECK(x[0]["ts"].get<double>() == 0.0001);
  CHECK(x[0]["dur"].get<double>() == 0.00005);
  CHECK(x[1]["ts"].get<double>() == 0.00015);
  CHECK(x[1]["dur"].get<double>() == 0.00005);
}

TEST_CASE("timeline: without close() no file is left behind", "[trace][timeline]") {
  const fs::path p = temp("abandoned.json");
  fs::remove(p);
  {
    TimelineWriter t(p.string());
    t.slice(t.track("top.gpp", "gpp", "GPP"), "issue", 0, 10);
  }
  CHECK_FALSE(fs::exists(p));
}
