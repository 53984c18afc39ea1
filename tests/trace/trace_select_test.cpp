// What --trace-frames, --trace-window, --trace-units and --trace-signals accept, what they
// reject (with the option and the problem), and which group and unit each signal belongs to.
#include "trace_select.h"

#include "base/error.h"

#include <catch2/catch.hpp>

using namespace oprt;

TEST_CASE("trace select: signals belong to a group and, per unit, to their unit", "[trace]") {
  CHECK(classify_signal("testbench.engine.iu12", "state").group == "state");
  CHECK(classify_signal("testbench.engine.iu12", "state").unit == 12);
  CHECK(classify_signal("testbench.engine.fifo3", "occupancy").group == "fifo");
  CHECK(classify_signal("testbench.engine.fifo3", "occupancy").unit == 3);
  CHECK(classify_signal("testbench.engine.bus", "busy").group == "bus");
  CHECK(classify_signal("testbench.engine.bus", "busy").unit == -1);
  CHECK(classify_signal("testbench.engine.gpp", "frame").group == "gpp");
  CHECK(classify_signal("testbench.engine.memory7", "misses").group == "memory");
  CHECK(classify_signal("testbench.engine.memory7", "misses").unit == 7);
  // A block inside a unit belongs to the unit: a pipelined unit's stages.
  CHECK(classify_signal("testbench.engine.iu5.stage", "triangle").unit == 5);
  CHECK(classify_signal("testbench.engine.iu5.stage", "triangle").group == "stage");
  // A signal no group claims has none.
  CHECK(classify_signal("testbench.engine.iu5.other", "x").unit == 5);
  CHECK(classify_signal("testbench.engine.iu5.other", "x").group.empty());
  CHECK(signal_groups() == std::vector<std::string>{"state", "fifo", "bus", "gpp", "memory", "stage"});
}

TEST_CASE("trace select: the selection keeps the chosen units' signals and every shared one", "[trace]") {
  TraceSelection s;
  s.units = {1, 3};
  s.groups = {"state", "bus"};
  CHECK(s.traces_signal("t.engine.iu1", "state"));
  CHECK_FALSE(s.traces_signal("t.engine.iu2", "state"));
  CHECK_FALSE(s.traces_signal("t.engine.fifo1", "occupancy"));  // group not chosen
  CHECK(s.traces_signal("t.engine.bus", "busy"));               // no unit: kept
  CHECK_FALSE(s.traces_signal("t.engine.gpp", "frame"));
}

TEST_CASE("trace select: good values", "[trace]") {
  CHECK(parse_trace_units("0-3,7") == std::vector<int>{0, 1, 2, 3, 7});
  CHECK(parse_trace_units(" 5 , 2-3,3") == std::vector<int>{2, 3, 5});
  std::uint64_t from, to;
  parse_trace_window("10us:2ms", from, to);
  CHECK(from == 10'000'000);
  CHECK(to == 2'000'000'000);
  parse_trace_window(":1.5ns", from, to);
  CHECK(from == 0);
  CHECK(to == 1500);
  parse_trace_window("0:", from, to);
  CHECK(to == TraceSelection::kNever);
  CHECK(parse_trace_signals("gpp,state") == std::vector<std::string>{"gpp", "state"});
  CHECK(parse_trace_frames("2:3", {0, 5}).first == 2);
  CHECK(parse_trace_frames("4", {0, 5}).last == 4);
  CHECK(format_time_ps(1'500'000'000) == "1.5ms");
  CHECK(format_time_ps(90'000) == "90ns");
  CHECK(format_time_ps(7) == "7ps");
}

TEST_CASE("trace select: bad values name the option, the value and the problem", "[trace]") {
  auto fails = [](auto&& f, const std::string& option, const std::string& problem) {
    try {
      f();
      FAIL("accepted");
    } catch (const InputError& e) {
      CHECK(e.file() == option);
      CHECK_THAT(e.problem(), Catch::Contains(problem));
    }
  };
  std::uint64_t a, b;
  fails([&] { parse_trace_window("2ms:1ms", a, b); }, "--trace-window", "must end after it starts");
  fails([&] { parse_trace_window("10:20", a, b); }, "--trace-window", "needs a unit");
  fails([&] { parse_trace_window("1xs:2ms", a, b); }, "--trace-window", "unknown time unit");
  fails([&] { parse_trace_window("1ms", a, b); }, "--trace-window", "expected T0:T1");
  fails([&] { parse_trace_window("-1us:2us", a, b); }, "--trace-window", "expected a time");
  fails([&] { parse_trace_units("3-1"); }, "--trace-units", "ends before it starts");
  fails([&] { parse_trace_units("1,,2"); }, "--trace-units", "expected units and ranges");
  fails([&] { parse_trace_units("x"); }, "--trace-units", "expected units and ranges");
  fails([&] { parse_trace_units(""); }, "--trace-units", "expected units and ranges");
  fails([&] { check_trace_units("0-40", parse_trace_units("0-40"), 32); }, "--trace-units",
        "unit 32 does not exist: this run has 32 units (0-31)");
  fails([&] { parse_trace_signals("state,wires"); }, "--trace-signals", "unknown signal group \"wires\"");
  fails([&] { parse_trace_signals(""); }, "--trace-signals", "empty signal group");
  fails([&] { parse_trace_frames("3:2", {0, 5}); }, "--trace-frames", "first frame is after the last");
  fails([&] { parse_trace_frames("4:9", {0, 5}); }, "--trace-frames", "renders frames 0:5 only");
  fails([&] { parse_trace_frames("a", {0, 5}); }, "--trace-frames", "expected a whole number in [0, 2147483647]");
}
