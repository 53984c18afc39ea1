// The waveform writer on hand-made changes: the exact VCD text for out-of-order reports,
// counters, windows and filters; a bounded buffer that writes the same file as an unbounded
// one; the FST it writes read back through GTKWave's own reader (fstapi).
#include "trace/vcd_writer.h"

#include "fstapi.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <map>
#include <random>
#include <sstream>

using namespace oprt;
namespace fs = std::filesystem;

namespace {

fs::path temp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("oprt_trace_tests_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The value-change part of a VCD (after $enddefinitions).
std::string changes(const std::string& vcd) {
  const auto at = vcd.find("$enddefinitions $end\n");
  REQUIRE(at != std::string::npos);
  return vcd.substr(at + 21);
}

}  // namespace

TEST_CASE("vcd writer: out-of-order changes come out in time order, the last of a time winning", "[trace]") {
  const fs::path p = temp("order.vcd");
  {
    VcdWriter w(p.string());
    const int a = w.add("top.u", "a", 3);
    const int b = w.add("top", "b", 1);
    w.change(a, 30, 2);
    w.change(b, 10, 1);
    w.change(a, 10, 5);
    w.change(a, 10, 4);  // same time, reported later: wins
    w.change(b, 20, 0);
    w.change(a, 20, 4);  // no change: not written
    w.close(40);
  }
  CHECK(slurp(p) ==
        "$version oprt $end\n$timescale 1ps $end\n"
        "$scope module top $end\n$var wire 1 \" b $end\n$scope module u $end\n$var wire 3 ! a $end\n"
        "$upscope $end\n$upscope $end\n$enddefinitions $end\n"
        "#0\nb0 !\n0\"\n#10\nb100 !\n1\"\n#20\n0\"\n#30\nb10 !\n#40\n");
}

TEST_CASE("vcd writer: a counter sums pushes and pops reported by two processes in their own orders", "[trace]") {
  const fs::path p = temp("counter.vcd");
  {
    VcdWriter w(p.string());
    const int c = w.add_counter("fifo0", "occupancy", 8);
    for (int i = 0; i < 3; ++i) w.change_by(c, 0, +1);  // three pushes at 0
    w.change_by(c, 5, -1);   // the unit, running ahead, pops at 5 and 10
    w.change_by(c, 10, -1);
    w.change_by(c, 2, +1);   // pushes at 2, 7 and 10 (the pop at 10 cancels it)
    w.change_by(c, 7, +1);
    w.change_by(c, 10, +1);
    w.change_by(c, 12, -1);
    w.close(12);
  }
  CHECK(changes(slurp(p)) == "#0\nb11 !\n#2\nb100 !\n#5\nb11 !\n#7\nb100 !\n#12\nb11 !\n");
}

TEST_CASE("vcd writer: the window starts with every value at its start and drops what follows its end", "[trace]") {
  const fs::path p = temp("window.vcd");
  {
    VcdWriter w(p.string());
    const int a = w.add("m", "a", 4);
    const int c = w.add_counter("m", "c", 4);
    w.set_window(100, 200);
    w.change(a, 60, 2);
    w.change(a, 50, 1);  // earlier, reported later: a is 2 at 100
    w.change_by(c, 60, 3);
    w.change_by(c, 100, 1);  // at the start: part of the first values
    w.change(a, 150, 3);
    w.change(a, 250, 4);
    w.close(300);
  }
  CHECK(changes(slurp(p)) == "#100\nb10 !\nb100 \"\n#150\nb11 !\n#200\n");
}

TEST_CASE("vcd writer: a window opened later (the first traced frame) starts with the values then", "[trace]") {
  const fs::path p = temp("frames.vcd");
  VcdWriter w(p.string());
  const int a = w.add("m", "a", 4);
  w.set_window(VcdWriter::kNever, VcdWriter::kNever);
  w.change(a, 10, 5);
  w.change(a, 90, 6);
  CHECK_THROWS_AS(w.set_window(80, VcdWriter::kNever), std::logic_error);  // a change at 90 is already folded
  w.set_window(90, VcdWriter::kNever);
  w.change(a, 95, 7);
  w.set_window(90, 120);  // the last traced frame ended
  w.change(a, 130, 8);
  w.close(140);
  CHECK(changes(slurp(p)) == "#90\nb110 !\n#95\nb111 !\n#120\n");
  CHECK(w.dump_start() == 90);
  CHECK(w.dump_end() == 120);
}

TEST_CASE("vcd writer: the filter leaves variables out of the file, and their changes", "[trace]") {
  const fs::path p = temp("filter.vcd");
  VcdWriter w(p.string());
  w.set_filter([](const std::string&, const std::string& name) { return name != "b"; });
  const int a = w.add("m", "a", 1);
  const int b = w.add("m", "b", 1);
  CHECK(b == VcdWriter::kNotTraced);
  w.change(b, 5, 1);
  w.change(a, 7, 1);
  w.close(10);
  CHECK(w.variables() == std::vector<std::pair<std::string, int>>{{"m.a", 1}});
  const std::string vcd = slurp(p);
  CHECK(vcd.find(" b $end") == std::string::npos);
  CHECK(changes(vcd) == "#0\n0!\n#7\n1!\n#10\n");
}

TEST_CASE("vcd writer: a change behind what was written is a bug, reported", "[trace]") {
  VcdWriter w(temp("late.vcd").string());
  const int a = w.add("m", "a", 1);
  w.change(a, 10, 1);
  w.flush_before(100);
  CHECK_THROWS_AS(w.change(a, 50, 0), std::logic_error);
  CHECK_THROWS_AS(w.add("m", "b", 1), std::logic_error);  // declared after the first change
}

TEST_CASE("vcd writer: a stopped run's trace forgets what follows its end", "[trace]") {
  const fs::path p = temp("discard.vcd");
  VcdWriter w(p.string());
  const int a = w.add("m", "a", 2);
  w.change(a, 10, 1);
  w.change(a, 20, 2);
  w.change(a, 30, 3);
  w.discard_from(20);
  w.close(25);
  CHECK(changes(slurp(p)) == "#0\nb0 !\n#10\nb1 !\n#25\n");
}

TEST_CASE("vcd writer: without close() no file is left behind", "[trace]") {
  const fs::path p = temp("abandoned.vcd");
  fs::remove(p);
  {
    VcdWriter w(p.string());
    const int a = w.add("m", "a", 1);
    w.change(a, 10, 1);
    w.flush_before(20);
  }
  CHECK_FALSE(fs::exists(p));
  for (const auto& e : fs::directory_iterator(p.parent_path())) CHECK(e.path().filename().string().rfind(".abandoned", 0) != 0);
}

// Units running ahead report far into the future; the horizon trails them. Flushing within
// the run (bounded) must write the same file as flushing only at the end.
TEST_CASE("vcd writer: flushing to a moving horizon bounds the buffer and writes the same file", "[trace]") {
  const fs::path bounded = temp("bounded.vcd"), whole = temp("whole.vcd");
  std::uint64_t horizon = 0;
  std::size_t peak = 0;
  {
    VcdWriter a(bounded.string()), b(whole.string());
    a.set_horizon([&] { return horizon; });
    std::vector<int> va, vb;
    for (int i = 0; i < 6; ++i) {
      const std::string s = "u" + std::to_string(i);
      va.push_back(i % 3 == 2 ? a.add_counter(s, "n", 16) : a.add(s, "state", 3));
      vb.push_back(i % 3 == 2 ? b.add_counter(s, "n", 16) : b.add(s, "state", 3));
    }
    std::mt19937_64 rng(7);
    std::vector<std::uint64_t> local(6, 0);  // each reporter's own time, ahead of the horizon
    for (int step = 0; step < 400000; ++step) {
      const int v = static_cast<int>(rng() % 6);
      local[v] = std::max(local[v], horizon) + rng() % 40;
      const std::uint64_t value = rng() % 6;
      if (v % 3 == 2) {
        const std::int64_t d = rng() % 2 ? 1 : -1;
        a.change_by(va[v], local[v], d);
        b.change_by(vb[v], local[v], d);
      } else {
        a.change(va[v], local[v], value);
        b.change(vb[v], local[v], value);
      }
      horizon = *std::min_element(local.begin(), local.end());  // no reporter is behind it
    }
    peak = a.peak_buffered();
    a.close(horizon + 1000);
    b.close(horizon + 1000);
  }
  CHECK(slurp(bounded) == slurp(whole));
  CHECK(peak < 2 * VcdWriter::kFlushEvery);
}

namespace {
// Every value change in an FST file, through GTKWave's reader: "name@time" -> value bits.
std::map<std::string, std::string> read_fst(const std::string& path) {
  void* r = fstReaderOpen(path.c_str());
  REQUIRE(r);
  std::map<fstHandle, std::string> names;
  std::vector<std::string> scope;
  while (fstHier* h = fstReaderIterateHier(r)) {
    if (h->htyp == FST_HT_SCOPE) scope.push_back(h->u.scope.name);
    else if (h->htyp == FST_HT_UPSCOPE) scope.pop_back();
    else if (h->htyp == FST_HT_VAR) {
      std::string n;
      for (const auto& s : scope) n += s + ".";
      names[h->u.var.handle] = n + h->u.var.name;
    }
  }
  fstReaderSetFacProcessMaskAll(r);
  struct Ctx {
    std::map<fstHandle, std::string>* names;
    std::map<std::string, std::string> values;
  } ctx{&names, {}};
  fstReaderIterBlocks(
      r,
      [](void* c, uint64_t t, fstHandle h, const unsigned char* v) {
        auto* x = static_cast<Ctx*>(c);
        x->values[(*x->names)[h] + "@" + std::to_string(t)] = reinterpret_cast<const char*>(v);
      },
      &ctx, nullptr);
  fstReaderClose(r);
  return ctx.values;
}
}  // namespace

TEST_CASE("vcd writer: a .fst path writes FST, which GTKWave's reader reads back", "[trace][fst]") {
  const fs::path p = temp("t.fst");
  {
    VcdWriter w(p.string());
    const int a = w.add("top.u", "a", 3);
    const int c = w.add_counter("top", "c", 8);
    w.change(a, 30, 2);
    w.change(a, 10, 5);
    w.change_by(c, 0, 4);
    w.change_by(c, 20, -1);
    w.close(40);
  }
  const auto v = read_fst(p.string());
  CHECK(v.at("top.u.a@0") == "000");
  CHECK(v.at("top.u.a@10") == "101");
  CHECK(v.at("top.u.a@30") == "010");
  CHECK(v.at("top.c@0") == "00000100");
  CHECK(v.at("top.c@20") == "00000011");
  CHECK(v.size() == 5);
}
