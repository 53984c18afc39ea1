// The trace options as a user types them: a bad value ends with exit status 2 and one line
// naming the option, the value and the problem, and writes no trace.
#include "cli_util.h"

#include <catch2/catch.hpp>

using namespace oprt::test;

namespace {
void check_rejected(const std::string& args, const std::string& says) {
  INFO(args);
  const fs::path d = temp_dir("trace_bad");
  const Result r = run_oprt("render " + scene("paper_room.json") + " --frames 0:1 --resolution 8x8 --no-progress --out " +
                            (d / "out").string() + " " + args);
  CHECK(r.status == 2);
  CHECK_THAT(r.output, Catch::Contains(says));
  CHECK_FALSE(fs::exists(d / "out" / "t.vcd"));
  CHECK_FALSE(fs::exists(d / "out" / "t.json"));
}
}  // namespace

TEST_CASE("cli: bad --trace-* values are rejected with the option, the value and the problem", "[cli][trace]") {
  const std::string vcd = " --vcd " + (fs::temp_directory_path() / "oprt_never_written.vcd").string();
  check_rejected("--trace-frames 1:0" + vcd, "--trace-frames: 1:0: first frame is after the last");
  check_rejected("--trace-frames 5" + vcd, "--trace-frames: 5: the run renders frames 0:1 only (--frames)");
  check_rejected("--trace-window 2ms:1ms" + vcd, "--trace-window: 2ms:1ms: the window must end after it starts");
  check_rejected("--trace-window 10:20" + vcd, "--trace-window: 10: a time needs a unit");
  check_rejected("--trace-window 1h:2h" + vcd, "--trace-window: 1h: unknown time unit \"h\"");
  check_rejected("--trace-units 0-99" + vcd, "--trace-units: 0-99: unit 32 does not exist: this run has 32 units (0-31)");
  check_rejected("--trace-units 3-1" + vcd, "--trace-units: 3-1: range 3-1 ends before it starts");
  check_rejected("--trace-signals state,nets" + vcd,
                 "--trace-signals: state,nets: unknown signal group \"nets\" (expected a list of: state, fifo, bus, gpp, memory, stage)");
  check_rejected("--trace-buffer 0" + vcd, "--trace-buffer");
}

TEST_CASE("cli: --trace-* without a trace to select from, and traces at the analytic level, are rejected", "[cli][trace]") {
  check_rejected("--trace-units 1", "--trace-units: 1: selects what --vcd or --timeline traces, and neither is given");
  check_rejected("--trace-buffer 100", "--trace-buffer: 100: sizes the --vcd writer's buffer, and --vcd is not given");
  check_rejected("--level analytic --timeline t.json", "--timeline: t.json: the analytic level has no simulated transactions");
}

TEST_CASE("cli: units running ahead keep the writer's buffer bounded when only their FIFOs are traced",
          "[cli][trace]") {
  // The room's 64x64 frame: 12,097 rays, each pushed into and popped from 32 FIFOs, so 774,208
  // occupancy changes; units running ahead would otherwise report their pops for the whole
  // frame ahead of simulation time.
  const fs::path d = temp_dir("trace_fifo_budget");
  const std::string common = "render " + scene("paper_room.json") +
                             " --frames 0 --resolution 64x64 --no-progress --trace-signals fifo --vcd ";
  const Result small = run_oprt(common + (d / "small" / "t.vcd").string() + " --trace-buffer 1000 --out " +
                                (d / "small").string());
  REQUIRE(small.status == 0);
  REQUIRE(run_oprt(common + (d / "default" / "t.vcd").string() + " --out " + (d / "default").string()).status == 0);
  const auto at = small.output.find("(at most ");
  REQUIRE(at != std::string::npos);
  const long held = std::stol(small.output.substr(at + 9));
  // --trace-buffer, the changes between two flushes (65,536) and what 32 units report within
  // 2^13 cycles of simulation time: far below the frame's changes.
  CHECK(held < 70000);
  CHECK(bytes_of(d / "small" / "t.vcd") == bytes_of(d / "default" / "t.vcd"));
}
