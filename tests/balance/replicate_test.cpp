// Copies of hot spheres (balance/replicate.h), on loads placed by hand.
#include "balance/replicate.h"

#include <catch2/catch.hpp>

using namespace oprt;

namespace {
Assignment of(std::vector<std::vector<std::uint32_t>> units) {
  Assignment a;
  a.unit = std::move(units);
  return a;
}
}  // namespace

TEST_CASE("replicate: a sphere heavier than the mean load is split until the units balance", "[balance][replicate]") {
  // Sphere 0 weighs 12, spheres 1-3 weigh 2 each, on 4 units: the partition's largest load is 12.
  ReplicateInputs in;
  in.weight = {12, 2, 2, 2};
  in.bytes = {10, 10, 10, 10};
  in.capacity = 100;
  const Assignment r = replicate(of({{0}, {1}, {2}, {3}}), in);
  // Copy 1 (unit 1, load 2 + 6 = 8 against unit 0's 6), copy 2 (units 2: 2 + 4; 0, 1: 4, 6),
  // copy 3 (unit 3: 2 + 3; 0: 3, 1 and 2: 5): every unit holds sphere 0, the largest load 5;
  // a fifth copy has no unit left.
  CHECK(r.unit == std::vector<std::vector<std::uint32_t>>{{0}, {0, 1}, {0, 2}, {0, 3}});
  const auto copies = replicas(r, 4);
  REQUIRE(copies.size() == 1);
  CHECK(copies[0].sphere == 0);
  CHECK(copies[0].units == std::vector<std::uint32_t>{0, 1, 2, 3});
  CHECK(replica_bytes(r, in.bytes) == 30);
}

TEST_CASE("replicate: at most N copies, only into memory that has room, none when nothing improves",
          "[balance][replicate]") {
  ReplicateInputs in;
  in.weight = {12, 2, 2, 2};
  in.bytes = {10, 10, 10, 10};
  in.capacity = 100;
  in.max_copies = 2;
  // Copy 1 of sphere 0 on unit 1 (loads 6, 8, 2, 2); sphere 0 has its two copies, so unit 1
  // gives a copy of sphere 1 to unit 2 (7 and 3); then no sphere of unit 1 may be copied.
  CHECK(replicate(of({{0}, {1}, {2}, {3}}), in).unit ==
        std::vector<std::vector<std::uint32_t>>{{0}, {0, 1}, {1, 2}, {3}});
  // Without a capacity, each unit has what the largest assignment needs (10 bytes): no room.
  in.capacity = 0;
  in.max_copies = 0;
  CHECK(replicate(of({{0}, {1}, {2}, {3}}), in).unit == std::vector<std::vector<std::uint32_t>>{{0}, {1}, {2}, {3}});
  // ... unless the partition leaves some units less full: unit 0 holds two spheres (20 bytes),
  // unit 1 none: sphere 0's copy goes there (loads 6, 6, 4, 2); unit 2 is full, and a copy
  // on unit 3 would not lower the largest load (6).
  in.weight = {12, 2, 2, 2, 0};
  in.bytes = {10, 10, 10, 10, 10};
  const Assignment r = replicate(of({{0, 4}, {}, {1, 2}, {3}}), in);
  CHECK(r.unit == std::vector<std::vector<std::uint32_t>>{{0, 4}, {0}, {1, 2}, {3}});
  // Balanced loads: no copy lowers the largest.
  in.weight = {3, 3, 3, 3};
  in.bytes = {1, 1, 1, 1};
  in.capacity = 100;
  CHECK(replicate(of({{0}, {1}, {2}, {3}}), in).unit == std::vector<std::vector<std::uint32_t>>{{0}, {1}, {2}, {3}});
}

TEST_CASE("replicate: the copies stay within their budget of bytes", "[balance][replicate]") {
  ReplicateInputs in;
  in.weight = {12, 2, 2, 2};
  in.bytes = {10, 10, 10, 10};
  in.capacity = 100;
  in.budget = 25;  // two copies of 10 bytes, not three
  CHECK(replicate(Assignment{{{0}, {1}, {2}, {3}}}, in).unit ==
        std::vector<std::vector<std::uint32_t>>{{0}, {0, 1}, {0, 2}, {3}});
}
