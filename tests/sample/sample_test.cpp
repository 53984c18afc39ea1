// Sampled simulation's pieces on hand-made inputs: which pixels (sample/pixel_sample.h) and
// the statistics of the sample (sample/strata.h).
#include "sample/pixel_sample.h"
#include "sample/strata.h"

#include "base/error.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>

using namespace oprt;

TEST_CASE("sample: fractions are 1/N, written so or as their decimal value", "[sample]") {
  CHECK(parse_sample_fraction("1/16", "--sample") == 16);
  CHECK(parse_sample_fraction("0.0625", "--sample") == 16);
  CHECK(parse_sample_fraction("0.25", "--sample") == 4);
  CHECK(parse_sample_fraction("1", "--sample") == 1);
  CHECK(parse_sample_fraction("1/1", "--sample") == 1);
  CHECK(parse_sample_fraction("0.1", "--sample") == 10);
  for (const char* bad : {"0", "0.3", "1/0", "2", "-0.5", "1/x", "", ".", "1e-2", "1/2/3", "1/2000000", "0.0000001"})
    CHECK_THROWS_AS(parse_sample_fraction(bad, "--sample"), InputError);
}

TEST_CASE("sample: one pixel in each block, blocks as square as N allows, edges cut", "[sample]") {
  const PixelSample s(10, 7, 16, 3);  // 4x4 blocks: 3 columns (4, 4, 2 wide) by 2 rows (4, 3 tall)
  CHECK(s.block_width() == 4);
  CHECK(s.block_height() == 4);
  REQUIRE(s.size() == 6);
  const std::uint32_t sizes[] = {16, 16, 8, 12, 12, 6};
  for (std::size_t i = 0; i < s.size(); ++i) {
    const int bx = static_cast<int>(i % 3) * 4, by = static_cast<int>(i / 3) * 4;
    const int x = static_cast<int>(s.pixel(i) % 10), y = static_cast<int>(s.pixel(i) / 10);
    CHECK(x >= bx);
    CHECK(x < std::min(bx + 4, 10));
    CHECK(y >= by);
    CHECK(y < std::min(by + 4, 7));
    CHECK(s.block_size(i) == sizes[i]);
  }
  // Groups: per row of 3 blocks, the third joins the first pair.
  CHECK(s.groups() == 2);
  CHECK(std::vector<std::uint32_t>{s.group(0), s.group(1), s.group(2), s.group(3), s.group(4), s.group(5)} ==
        std::vector<std::uint32_t>{0, 0, 0, 1, 1, 1});
  CHECK(PixelSample(8, 8, 8, 0).block_width() == 4);
  CHECK(PixelSample(8, 8, 8, 0).block_height() == 2);
  CHECK(PixelSample(8, 8, 7, 0).block_width() == 7);
  const PixelSample all(5, 3, 1, 9);  // N = 1: every pixel, in scan order
  REQUIRE(all.size() == 15);
  for (std::uint32_t p = 0; p < 15; ++p) CHECK(all.pixel(p) == p);
}

TEST_CASE("sample: each pixel of a block equally likely over seeds; the same seed, the same pixels", "[sample]") {
  std::vector<int> count(16, 0);
  for (std::uint64_t seed = 0; seed < 16000; ++seed) ++count[PixelSample(4, 4, 16, seed).pixel(0)];
  for (int c : count) CHECK(std::abs(c - 1000) < 120);  // 1000 expected, sd 31
  CHECK(PixelSample(64, 48, 16, 5).pixels() == PixelSample(64, 48, 16, 5).pixels());
  CHECK(PixelSample(64, 48, 16, 5).pixels() != PixelSample(64, 48, 16, 6).pixels());
}

TEST_CASE("strata: Horvitz-Thompson totals and collapsed-strata variances by hand", "[sample][strata]") {
  // Four pixels in two groups; blocks of 4 pixels except the last (2); figure 0 varies, 1 does not.
  const std::vector<double> y = {1, 2, 3, 2, 5, 2, 5, 2};
  const std::vector<std::uint32_t> size = {4, 4, 4, 2}, group = {0, 0, 1, 1};
  const sample::Strata s(y.data(), 2, size, group, 2);
  CHECK(s.total(0) == 4 + 12 + 20 + 10);
  CHECK(s.sample_sum(0) == 14);
  // Group 0: T = 4, 12 (N 8): deviations 4 - 8 = -4, 12 - 8 = 4, factor 2: 2 x 32 = 64.
  // Group 1: T = 20, 10 (N 6, T_g 30): 20 - 20 = 0, 10 - 10 = 0 (the same per-pixel value).
  CHECK(s.variance(0) == Approx(64));
  // A figure constant per pixel has no variance, whatever the block sizes.
  CHECK(s.variance(1) == Approx(0).margin(1e-12));
  const auto c = s.covariance({0, 1});
  CHECK(c[0] == Approx(64));
  CHECK(c[1] == Approx(0).margin(1e-12));
  const auto w = s.covariance_with({2, 0}, {0});  // 2 x figure 0
  CHECK(w[0] == Approx(128));
  CHECK(w[1] == Approx(256));
  CHECK(s.series_total({1, 3, 5, 5}) == s.total(0));
  CHECK(s.series_variance({1, 3, 5, 5}) == Approx(64));
}

TEST_CASE("strata: the bootstrap's bias of a maximum: none for one total far above, 0.56 sd for two equal ones",
          "[sample][strata]") {
  const auto maxima = [](const std::vector<double>& mean, const std::vector<double>& cov) {
    std::vector<double> m;
    for (const auto& d : sample::normal_draws(mean, cov, 20000, 1)) m.push_back(*std::max_element(d.begin(), d.end()));
    return m;
  };
  const sample::MaxEstimate far = sample::max_from_draws(maxima({100, 10}, {1, 0, 0, 1}), 100, 0);
  CHECK(far.bias == Approx(0).margin(0.03));
  CHECK(far.low == Approx(100 - sample::kZ95).margin(0.1));
  CHECK(far.high == Approx(100 + sample::kZ95).margin(0.1));
  // E[max of two independent N(0, 1)] = 1 / sqrt(pi) = 0.564.
  const sample::MaxEstimate tie = sample::max_from_draws(maxima({50, 50}, {4, 0, 0, 4}), 50, 0);
  CHECK(tie.bias == Approx(2 * 0.5642).margin(0.05));
  CHECK(tie.estimate() == Approx(50 - 2 * 0.5642).margin(0.05));
  // Perfectly correlated: the same total twice, no bias.
  CHECK(sample::max_from_draws(maxima({50, 50}, {4, 4, 4, 4}), 50, 0).bias == Approx(0).margin(0.03));
  // The same seed draws the same numbers.
  CHECK(sample::normal_draws({0}, {1}, 3, 7) == sample::normal_draws({0}, {1}, 3, 7));
}
