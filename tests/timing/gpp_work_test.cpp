// GppWork (timing/gpp_plan.h), the order of the GPP's work at every level, on a hand-made
// frame whose rays spawn rays: a spawned ray is queued only when its parent retires, and the
// latencies, spawn delays and starved time it measures are the hand-computed ones.
#include "timing/gpp_plan.h"

#include <catch2/catch.hpp>

#include <cstdint>
#include <map>
#include <vector>

using namespace oprt;
using namespace oprt::timing;

namespace {
RayRecord<float> record(RayKind kind, int depth, std::uint32_t pixel, bool hit, std::uint32_t first_child = 0,
                        std::uint32_t children = 0) {
  RayRecord<float> r;
  r.kind = kind;
  r.depth = static_cast<std::uint8_t>(depth);
  r.pixel = pixel;
  r.first_child = first_child;  // relative to the ray's id
  r.children = children;
  if (hit) r.object = 0, r.prim = 0, r.t = 1;
  return r;
}

// Pixel 0: its primary ray (0) hits and spawns a shadow ray (1), a reflection ray (2) and a
// refraction ray (3); the reflection hits and spawns a shadow ray (4); the refraction misses.
// Pixel 1: its primary ray (5) misses.
FunctionalFrame<float> frame() {
  FunctionalFrame<float> f;
  f.rays = {record(RayKind::primary, 0, 0, true, 1, 3), record(RayKind::shadow, 0, 0, false),
            record(RayKind::reflection, 1, 0, true, 2, 1), record(RayKind::refraction, 1, 0, false),
            record(RayKind::shadow, 1, 0, false), record(RayKind::primary, 0, 1, false)};
  f.pixel_rays = {0, 5, 6};
  return f;
}

struct Event {
  char what;  // 'i' issue, 'r' retire
  std::uint32_t ray;
  std::uint64_t at;
};
}  // namespace

TEST_CASE("gpp work: a spawned ray is issued only after its parent retires, in the order its hit spawned it",
          "[timing][gpp][whitted]") {
  const FunctionalFrame<float> f = frame();
  GppWork<float, std::uint64_t> work(f);
  constexpr std::uint64_t never = ~std::uint64_t{0};
  // The GPP takes 4 cycles to issue a ray and 30 to shade a hit; every ray's answers are in
  // 100 cycles after its issue ends; FIFOs always have room.
  std::uint64_t now = 0;
  std::size_t issued = 0, retired = 0;
  std::vector<Event> events;
  for (int guard = 0; guard < 100; ++guard) {
    const std::uint64_t room = work.has_ray() ? now : never;
    const auto next = work.next(now, room, never, work.due(never) == never && issued == retired);
    if (next == GppWork<float, std::uint64_t>::Next::done) break;
    if (next == GppWork<float, std::uint64_t>::Next::retire) {
      const auto r = work.retire();
      events.push_back({'r', r.ray, now});
      ++retired;
      if (r.shade) now += 30;
    } else if (next == GppWork<float, std::uint64_t>::Next::issue) {
      const std::uint32_t id = work.take_ray(now);
      events.push_back({'i', id, now});
      ++issued;
      now += 4;
      work.answered(now + 100, id);
    } else {
      now = work.due(never);
    }
  }
  CHECK(issued == 6);
  CHECK(retired == 6);
  // By hand: both primaries go out first (0 at 0, 5 at 4); ray 0's answers are in at 104, it
  // is shaded until 134, then its children go out in spawn order: 1 at 134, 2 at 138, 3 at
  // 142. Ray 5 (answers at 108) retires at 134, after ray 0's shading. Ray 1 answers at 238,
  // 2 at 242 (shaded until 272), 3 at 246; ray 2's child 4 goes out at 272 and answers at 376.
  const std::vector<Event> want = {{'i', 0, 0},   {'i', 5, 4},   {'r', 0, 104}, {'r', 5, 134}, {'i', 1, 134},
                                   {'i', 2, 138}, {'i', 3, 142}, {'r', 1, 238}, {'r', 2, 242}, {'r', 3, 272},
                                   {'i', 4, 272}, {'r', 4, 376}};
  REQUIRE(events.size() == want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    INFO("event " << i);
    CHECK(events[i].what == want[i].what);
    CHECK(events[i].ray == want[i].ray);
    CHECK(events[i].at == want[i].at);
  }
  // Every spawned ray is issued after its parent retired and was shaded.
  std::map<std::uint32_t, std::uint64_t> issue, retire;
  for (const Event& e : events) (e.what == 'i' ? issue : retire)[e.ray] = e.at;
  int children = 0;
  for (std::uint32_t p = 0; p < f.ray_count(); ++p) {
    const RayRecord<float>& r = f.rays[p];
    for (std::uint32_t c = p + r.first_child; r.children && c < p + r.first_child + r.children; ++c, ++children)
      CHECK(issue[c] >= retire[p] + 30);
  }
  CHECK(children == 4);

  // Latency (issue to last answer) per kind, and spawn delay (parent's issue to own issue):
  // primary 104 + (108 - 4) = 208; shadow (238 - 134) + (376 - 272) = 208; reflection 104;
  // refraction 104. Spawn delays: shadow (134 - 0) + (272 - 138) = 268; reflection 138;
  // refraction 142; primary none.
  const Waiting<std::uint64_t>& w = work.waiting();
  CHECK(w.latency[0] == 208);
  CHECK(w.latency[1] == 208);
  CHECK(w.latency[2] == 104);
  CHECK(w.latency[3] == 104);
  CHECK(w.spawn_delay[0] == 0);
  CHECK(w.spawn_delay[1] == 268);
  CHECK(w.spawn_delay[2] == 138);
  CHECK(w.spawn_delay[3] == 142);
  // Starved: no ray to issue while rays were in flight: 8 -> 104 (after the primaries), 146
  // -> 242 (after ray 0's children; ray 1 retires at 238 and spawns nothing), 276 -> 376
  // (after ray 4).
  CHECK(w.starved == (104 - 8) + (242 - 146) + (376 - 276));
}
