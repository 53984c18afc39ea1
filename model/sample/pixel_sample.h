// Sampled simulation (--sample F, --seed S): which pixels of a frame are traced. The image is
// cut into blocks of n = 1/F pixels (bw x bh, as square as n allows: 16 is 4x4, 8 is 4x2,
// 7 is 7x1) from its top-left corner; blocks on the right and bottom edges are cut by the
// image (fewer pixels). Each block contributes one pixel, at an offset drawn from the seed
// and the block's index alone (jittered stratified sampling): every pixel of a block of
// N_b pixels is taken with probability 1 / N_b, so N_b times a sampled pixel's figure is an
// unbiased estimate of its block's total (Horvitz-Thompson), and the sum over blocks of the
// frame's. A pixel's whole ray tree comes with it. The same pixels in every frame.
//
// The sampled pixels are issued in the order of their blocks, row by row: the sample's scan
// keeps the frame's progression (a row of blocks stands for bh rows of the frame).
// For the variance, neighbouring blocks of a row are paired ("collapsed strata": one pixel
// per block gives no variance within a block); a row of blocks with an odd count puts its
// last block with the pair before it, a row of one block joins the row above's last group.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace oprt {

// "1/N" (N a whole number from 1 to 2^20) or a decimal number in (0, 1] whose inverse is a
// whole number ("0.0625" is 1/16, "0.25", "0.5", "1"); returns N. Throws InputError naming
// the option otherwise.
std::uint32_t parse_sample_fraction(const std::string& text, const std::string& option);

class PixelSample {
 public:
  // n = 1 samples every pixel (each its own block).
  PixelSample(int width, int height, std::uint32_t n, std::uint64_t seed);

  std::uint32_t n() const { return n_; }
  std::uint64_t seed() const { return seed_; }
  int block_width() const { return bw_; }
  int block_height() const { return bh_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::uint64_t frame_pixels() const { return static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_); }
  // "1/16"
  std::string fraction_text() const { return "1/" + std::to_string(n_); }

  std::size_t size() const { return pixels_.size(); }
  // The frame's pixel (y * width + x) of sample i, in issue order.
  std::uint32_t pixel(std::size_t i) const { return pixels_[i]; }
  const std::vector<std::uint32_t>& pixels() const { return pixels_; }
  // Pixels in sample i's block (n, or fewer on the image's right and bottom edges).
  std::uint32_t block_size(std::size_t i) const { return block_size_[i]; }
  const std::vector<std::uint32_t>& block_sizes() const { return block_size_; }
  // The group (pair, or three) sample i's block is collapsed with for the variance;
  // groups are numbered 0 .. groups() - 1 and each holds consecutive samples.
  std::uint32_t group(std::size_t i) const { return group_[i]; }
  const std::vector<std::uint32_t>& group_of() const { return group_; }
  std::uint32_t groups() const { return groups_; }

 private:
  int width_, height_, bw_ = 1, bh_ = 1;
  std::uint32_t n_;
  std::uint64_t seed_;
  std::vector<std::uint32_t> pixels_, block_size_, group_;
  std::uint32_t groups_ = 0;
};

// A block's offset: splitmix64 of the seed and the block's index (exposed for tests).
std::uint64_t sample_hash(std::uint64_t seed, std::uint64_t block);

}  // namespace oprt
