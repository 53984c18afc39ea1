#include "sample/pixel_sample.h"

#include "base/error.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace oprt {

namespace {
constexpr std::uint32_t kMaxSampleN = 1u << 20;

std::uint32_t whole(const std::string& text, const std::string& option, const std::string& digits) {
  if (digits.empty() || digits.size() > 7 || digits.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(option, text, "expected a fraction 1/N (N a whole number, 1 to 1048576) or its decimal value (0.0625)");
  const unsigned long n = std::stoul(digits);
  if (n < 1 || n > kMaxSampleN) throw InputError(option, text, "N of 1/N must be from 1 to 1048576");
  return static_cast<std::uint32_t>(n);
}
}  // namespace

std::uint32_t parse_sample_fraction(const std::string& text, const std::string& option) {
  if (text.rfind("1/", 0) == 0) return whole(text, option, text.substr(2));
  // A decimal: digits and one point, no sign or exponent.
  const bool decimal = !text.empty() && text.find_first_not_of("0123456789.") == std::string::npos &&
                       std::count(text.begin(), text.end(), '.') <= 1 && text != ".";
  if (!decimal) throw InputError(option, text, "expected a fraction 1/N (such as 1/16) or its decimal value (0.0625)");
  const double f = std::strtod(text.c_str(), nullptr);
  if (!(f > 0) || f > 1) throw InputError(option, text, "the fraction of the pixels must be above 0 and at most 1");
  const double inverse = 1 / f;
  const double n = std::round(inverse);
  if (n > kMaxSampleN || std::fabs(inverse - n) > 1e-9 * n)
    throw InputError(option, text, "not 1/N for a whole N (write 1/N: 1/16 is 0.0625, 1/3 has no exact decimal)");
  return static_cast<std::uint32_t>(n);
}

std::uint64_t sample_hash(std::uint64_t seed, std::uint64_t block) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + block + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

PixelSample::PixelSample(int width, int height, std::uint32_t n, std::uint64_t seed)
    : width_(width), height_(height), n_(n), seed_(seed) {
  for (std::uint32_t d = 1; std::uint64_t{d} * d <= n; ++d)
    if (n % d == 0) bh_ = static_cast<int>(d);
  bw_ = static_cast<int>(n / static_cast<std::uint32_t>(bh_));
  const int columns = (width + bw_ - 1) / bw_, rows = (height + bh_ - 1) / bh_;
  pixels_.reserve(static_cast<std::size_t>(columns) * rows);
  for (int by = 0; by < rows; ++by) {
    const std::uint32_t row_first_group = groups_;
    for (int bx = 0; bx < columns; ++bx) {
      const int x0 = bx * bw_, y0 = by * bh_;
      const int w = std::min(bw_, width - x0), h = std::min(bh_, height - y0);
      const auto size = static_cast<std::uint32_t>(w * h);
      const std::uint64_t block = static_cast<std::uint64_t>(by) * static_cast<std::uint64_t>(columns) + bx;
      const auto k = static_cast<int>(sample_hash(seed, block) % size);
      pixels_.push_back(static_cast<std::uint32_t>((y0 + k / w) * width + x0 + k % w));
      block_size_.push_back(size);
      // Pairs along the row; the last block of an odd row joins the pair before it.
      const bool joins = bx == columns - 1 && bx % 2 == 0 && bx > 0;
      group_.push_back(joins ? groups_ - 1 : row_first_group + static_cast<std::uint32_t>(bx / 2));
      if (!joins && bx % 2 == 0) ++groups_;
    }
    if (columns == 1 && by > 0) {  // a lone block: with the row above's last group
      group_.back() = row_first_group - 1;
      --groups_;
    }
  }
  if (groups_ == 0) groups_ = 1;  // a single block: one group (its variance is unknown)
}

}  // namespace oprt
