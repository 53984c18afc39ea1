// The shared bus's arbiters on their own, in plain integer time: what a request gets when
// requests arrive out of time order, as they do under temporal decoupling.
#include "timing/calendar.h"

#include <catch2/catch.hpp>

using oprt::timing::Arbiter;
using oprt::timing::BusyUntil;
using oprt::timing::Calendar;

TEST_CASE("calendar: requests in time order are first come first served", "[calendar]") {
  Calendar<int> c;
  BusyUntil<int> b;
  // (request, length) -> end of the grant, by hand: [0,4) [4,10) [10,12) [20,23) [23,24)
  const int req[][3] = {{0, 4, 4}, {1, 6, 10}, {2, 2, 12}, {20, 3, 23}, {20, 1, 24}};
  for (const auto& r : req) {
    CHECK(c.reserve(r[0], r[1]) == r[2]);
    CHECK(b.reserve(r[0], r[1]) == r[2]);
  }
}

TEST_CASE("calendar: a late-arriving earlier request takes the first gap at or after its time", "[calendar]") {
  Calendar<int> c;
  BusyUntil<int> naive;
  int start = -1;
  // A unit running ahead books [100, 110) first; then requests stamped earlier arrive.
  CHECK(c.reserve(100, 10) == 110);
  CHECK(c.reserve(20, 5, &start) == 25);  // the bus is free at 20
  CHECK(start == 20);
  CHECK(c.reserve(22, 5, &start) == 30);  // behind [20, 25) only
  CHECK(start == 25);
  CHECK(c.reserve(95, 5, &start) == 100);  // fits exactly before [100, 110)
  CHECK(start == 95);
  CHECK(c.reserve(96, 10, &start) == 120);  // does not fit anywhere before 110
  CHECK(start == 110);
  // Gaps are now [0, 20) and [30, 95): 60 cycles fit only in the second.
  CHECK(c.reserve(0, 60, &start) == 90);
  CHECK(start == 30);
  // The naive arbiter queues every one of them behind the latest grant.
  CHECK(naive.reserve(100, 10) == 110);
  CHECK(naive.reserve(20, 5) == 115);
  CHECK(naive.reserve(22, 5) == 120);
}

TEST_CASE("calendar: forgetting the past keeps later grants", "[calendar]") {
  Calendar<int> c;
  c.reserve(0, 10);
  c.reserve(50, 10);
  c.forget_before(10);  // [0, 10) is dropped: every later request is stamped 10 or later
  CHECK(c.reserve(10, 40) == 50);
  CHECK(c.reserve(52, 1) == 61);  // [50, 60) is still booked
  Arbiter<int> cal(false), busy(true);
  cal.reserve(100, 10);
  busy.reserve(100, 10);
  CHECK(cal.reserve(0, 5) == 5);
  CHECK(busy.reserve(0, 5) == 115);
}
