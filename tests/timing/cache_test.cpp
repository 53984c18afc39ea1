// The object memory as a cache (timing/cache.h, timing/object_memory_model.h): replacement
// by hand-worked access sequences, the miss window, and the timing of a serial unit's visit
// through the cache (timing/serial_unit_timing.h) worked out cycle by cycle; with every line
// present, the on-chip memory's own timing (stream_stall) exactly.
#include "timing/cache.h"
#include "ref/memory_timing.h"
#include "timing/object_memory_model.h"
#include "timing/serial_unit_timing.h"

#include <catch2/catch.hpp>

#include <random>

using namespace oprt;
using namespace oprt::timing;

namespace {
// Lines 0, 2, 4, ... share set 0 of a two-set, two-way cache of 64-byte lines.
std::string pattern(CacheReplacement r, const std::vector<std::uint64_t>& lines) {
  Cache c(256, 64, 2, r, 1);
  std::string s;
  for (std::uint64_t l : lines) {
    bool hit = false;
    c.access(l, hit);
    s += hit ? 'h' : 'm';
  }
  return s;
}

constexpr std::uint32_t kMoller[4] = {4, 14, 17, 22};

VisitCosts costs(Cycle lead) { return {lead, kMoller, 13}; }

// DRAM that answers every miss 50 cycles after it is sent, recording the sends.
struct FixedDram final : ObjectMemoryModel::Fill {
  std::vector<Cycle> sent;
  Cycle fetch(std::uint64_t, Cycle t) override {
    sent.push_back(t);
    return t + 50;
  }
};

// An object memory of `sram` bytes that is a cache (lines of 64 bytes, 4 ways), `misses`
// in flight, its misses answered by `dram`; on-chip latency 10, 16 bytes per cycle if `latency`.
struct CacheMemory {
  Arch arch;
  std::unique_ptr<ObjectMemoryModel> model;
  CacheMemory(std::uint64_t sram, int misses, ObjectMemoryModel::Fill& dram, bool latency = false) {
    arch.memory.sram_bytes = sram;
    arch.memory.cache.misses_outstanding = misses;
    arch.memory.model = latency ? MemoryModel::latency : MemoryModel::ideal;
    arch.memory.latency_cycles = 10;
    arch.memory.bytes_per_cycle = 16;
    model = std::make_unique<ObjectMemoryModel>(arch, 0);
    MemoryLoad l;
    l.cache = true;
    model->load(l);
    model->set_fill(&dram);
  }
};

// A serial unit's visit from `start` (its sphere hit) through memory m: its end and stall.
struct Timed {
  Cycle end, stall;
};
template <typename State>
Timed serial_visit(ObjectMemoryModel& m, const VisitStream& v, Cycle start, Cycle lead, State&& state) {
  const VisitCosts c = costs(lead);
  SerialVisit<State> unit(c, start, state);
  m.visit(v, start, unit);
  return {unit.end(), unit.stall()};
}
auto no_state = [](UnitState, Cycle) {};
}  // namespace

TEST_CASE("cache: lru evicts the least recently used way of the set, fifo the first filled", "[cache]") {
  //                                        0    2    0    4    2    0
  CHECK(pattern(CacheReplacement::lru, {0, 2, 0, 4, 2, 0}) == "mmhmmm");   // 4 evicts 2, 2 evicts 0, 0 evicts 4
  CHECK(pattern(CacheReplacement::lru, {0, 2, 0, 4, 0, 2}) == "mmhmhm");   // 0 was used after 2: 4 evicts 2
  CHECK(pattern(CacheReplacement::fifo, {0, 2, 0, 4, 0, 2}) == "mmhmmm");  // 4 evicts 0 (filled first) despite its use
  // The other set is independent; a line is its own set's.
  CHECK(pattern(CacheReplacement::lru, {1, 3, 0, 2, 1, 3}) == "mmmmhh");
  // Random: the same victims on every run (seeded), and a full set still misses new lines.
  CHECK(pattern(CacheReplacement::random, {0, 2, 4, 6, 8, 0, 2}) == pattern(CacheReplacement::random, {0, 2, 4, 6, 8, 0, 2}));
  CHECK(pattern(CacheReplacement::random, {0, 2, 4, 6, 8}) == "mmmmm");
}

TEST_CASE("cache: invalidated lines miss again, others stay", "[cache]") {
  Cache c(1024, 64, 4, CacheReplacement::lru, 1);
  bool hit = false;
  for (std::uint64_t l = 0; l < 8; ++l) c.access(l, hit);
  c.invalidate(2, 5);
  std::string s;
  for (std::uint64_t l = 0; l < 8; ++l) {
    c.access(l, hit);
    s += hit ? 'h' : 'm';
  }
  CHECK(s == "hhmmmhhh");
}

TEST_CASE("cache: a full miss window sends the next miss when the oldest arrives", "[cache]") {
  MissWindow w(2);
  CHECK(w.slot(0) == 0);
  w.sent(10);
  CHECK(w.slot(0) == 0);
  w.sent(20);
  CHECK(w.slot(0) == 10);  // both slots taken: wait for the miss arriving at 10
  w.sent(30);
  CHECK(w.slot(25) == 25);  // the one due at 20 has arrived by 25: a slot is free
}

TEST_CASE("cache: a brute-force visit through a cold cache, cycle by cycle", "[cache]") {
  // Three triangles of 48 bytes from address 0 cover lines 0, 1, 2 (64 bytes each); exit
  // stage t (22 cycles) each; the transform (19) leads. Every line misses; DRAM answers 50
  // cycles after a miss is sent.
  VisitStream v;
  v.stages = {3, 3, 3};
  v.bursts = {{0, 3, 48, false}};
  SECTION("four misses in flight: all three sent at once, at the sphere hit") {
    FixedDram dram;
    CacheMemory m(4096, 4, dram);
    // triangle 0 waits for line 0 (19 -> 50), ends 72; 1 and 2 find their lines there.
    const Timed t = serial_visit(*m.model, v, 0, 19, no_state);
    CHECK(t.end == 116);
    CHECK(dram.sent == std::vector<Cycle>{0, 0, 0});
    CHECK(t.stall == 31);
    const CacheCounts& n = m.model->counts();
    CHECK(n.misses == 3);
    CHECK(n.hits == 0);  // a line shared by consecutive triangles is looked up once
    CHECK(n.dram_bytes == 3 * 64);
    // Again from 200: every line is there, no stall: 200 + 19 + 3 x 22.
    const Timed again = serial_visit(*m.model, v, 200, 19, no_state);
    CHECK(again.end == 285);
    CHECK(n.hits == 3);
    CHECK(again.stall == 0);
  }
  SECTION("one miss in flight: each line is sent when the previous one arrives") {
    FixedDram dram;
    CacheMemory m(4096, 1, dram);
    // lines arrive at 50, 100, 150: triangle 0 19 -> 50 -> 72; 1 waits to 100 -> 122;
    // 2 waits to 150 -> 172.
    const Timed t = serial_visit(*m.model, v, 0, 19, no_state);
    CHECK(t.end == 172);
    CHECK(dram.sent == std::vector<Cycle>{0, 50, 100});
    CHECK(t.stall == 31 + 28 + 28);
  }
}

TEST_CASE("cache: a BVH visit's node and leaf are dependent bursts through the cache", "[cache][bvh]") {
  // Node at 4096 (one line), then its leaf: two triangles at 0 (lines 0 and 1), exit
  // stages det (4) and t (22). Lead: transform 19 + box set-up 12.
  VisitStream v;
  v.stages = {kLogNode, 0, 3};
  v.bursts = {{4096, 1, 32, true}, {0, 2, 48, false}};
  FixedDram dram;
  CacheMemory m(4096, 4, dram);
  std::vector<std::pair<UnitState, Cycle>> states;
  // The node is sent at the hit (0), arrives at 50: stall 31 -> 50, box test to 63. Then
  // the leaf's lines are sent at 63, arrive at 113: stall, triangle 0 to 117, 1 to 139.
  const Timed t = serial_visit(*m.model, v, 0, 31, [&](UnitState s, Cycle c) { states.emplace_back(s, c); });
  CHECK(t.end == 139);
  CHECK(dram.sent == std::vector<Cycle>{0, 63, 63});
  CHECK(t.stall == 19 + 50);
  CHECK(states == std::vector<std::pair<UnitState, Cycle>>{
                      {UnitState::stall, 31}, {UnitState::box, 50}, {UnitState::stall, 63}, {UnitState::primitive, 113}});
}

TEST_CASE("cache: with every line present a visit takes what on-chip memory takes (stream_stall)", "[cache]") {
  std::mt19937_64 rng(11);
  for (bool latency : {false, true}) {
    for (int trial = 0; trial < 200; ++trial) {
      // A random walk's log: nodes and leaves of 1 to 8 triangles, or one brute-force burst.
      VisitStream v;
      const bool bvh = trial % 2;
      std::uint64_t tri = 0, node = 0;
      if (!bvh) {
        const std::uint32_t n = 1 + rng() % 60;
        for (std::uint32_t i = 0; i < n; ++i) v.stages.push_back(static_cast<std::uint8_t>(rng() % 4));
        v.bursts = {{48 * (rng() % 1000), n, 48, false}};
      } else {
        for (int k = 0; k < 1 + static_cast<int>(rng() % 12); ++k) {
          v.stages.push_back(kLogNode);
          v.bursts.push_back({1 << 20 | 32 * (node += 1 + rng() % 5), 1, 32, true});
          if (rng() % 2) continue;
          const std::uint32_t n = 1 + rng() % 8;
          for (std::uint32_t i = 0; i < n; ++i) v.stages.push_back(static_cast<std::uint8_t>(rng() % 4));
          v.bursts.push_back({48 * (tri += 8 + rng() % 40), n, 48, false});
        }
      }
      // Warm the cache (large enough to keep everything), then time from far later.
      FixedDram dram;
      CacheMemory m(1 << 22, 4, dram, latency);
      const Cycle lead = bvh ? 31 : 19;
      serial_visit(*m.model, v, 0, lead, no_state);
      const std::uint64_t misses = m.model->counts().misses;
      const Cycle start = 1000000;
      const Timed t = serial_visit(*m.model, v, start, lead, no_state);
      INFO("trial " << trial << (latency ? " latency" : " ideal"));
      REQUIRE(m.model->counts().misses == misses);  // the second time, no miss
      StreamCosts onchip;
      onchip.latency = 10;
      onchip.bytes_per_cycle = 16;
      onchip.triangle_bytes = 48;
      onchip.node_bytes = 32;
      onchip.lead = static_cast<std::uint32_t>(lead);
      onchip.triangle = kMoller;
      onchip.box = 13;
      const std::uint64_t expect = latency ? stream_stall(onchip, v.stages.data(), static_cast<std::uint32_t>(v.stages.size())) : 0;
      REQUIRE(static_cast<std::uint64_t>(t.stall) == expect);
      std::uint64_t work = static_cast<std::uint64_t>(lead);
      for (std::uint8_t s : v.stages) work += s == kLogNode ? 13 : kMoller[s];
      REQUIRE(static_cast<std::uint64_t>(t.end) == static_cast<std::uint64_t>(start) + work + expect);
    }
  }
}

TEST_CASE("cache: an empty way is filled before any line is evicted, under every policy and seed", "[cache]") {
  // One set of four ways (256 bytes of 64-byte lines): four different lines all fit, so after
  // they are read once each of them hits, whatever the replacement and its random seed.
  for (CacheReplacement r : {CacheReplacement::lru, CacheReplacement::fifo, CacheReplacement::random})
    for (std::uint64_t seed = 0; seed < 16; ++seed) {
      INFO("policy " << static_cast<int>(r) << " seed " << seed);
      Cache c(256, 64, 4, r, seed);
      std::string s;
      for (std::uint64_t l : {0, 1, 2, 3, 0, 1, 2, 3}) {
        bool hit = false;
        c.access(l, hit);
        s += hit ? 'h' : 'm';
      }
      CHECK(s == "mmmmhhhh");
    }
}
