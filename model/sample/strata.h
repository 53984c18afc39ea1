// The statistics of a stratified sample with one unit per stratum (sample/pixel_sample.h):
// Horvitz-Thompson totals, their variances and covariances by collapsed strata, and the
// distribution of a maximum of such totals by a parametric bootstrap. Plain C++.
//
// Each sampled pixel i stands for its block of N_i pixels: T_i = N_i y_i is its block's
// estimated total (y_i the pixel's figures), and sum_i T_i the frame's (unbiased). One pixel
// per block leaves no variance within a block to measure, so blocks are collapsed into
// groups of 2 or 3 neighbours and each group treated as a stratum sampled g times
// (Cochran, Sampling Techniques, 5A.12; Hansen, Hurwitz and Madow for unequal sizes):
//   V = sum over groups g/(g-1) sum_{i in g} (T_i - (N_i/N_g) T_g)^2
// with T_g and N_g the group's sums. It over-states the variance by what neighbouring
// blocks' means differ: a safe error bar.
//
// A maximum of totals (the makespan is set by the busiest of several resources) is biased
// upward when several are close: E[max X] >= max E[X]. bootstrap_max draws the totals from
// the normal distribution with the estimated covariance and returns the bias and the
// quantiles of the maximum (the distribution of the maximum is skewed when totals are close).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace oprt::sample {

constexpr double kConfidence = 0.95;
constexpr double kZ95 = 1.959963984540054;  // the normal distribution's 97.5 % quantile

// Per-pixel figures of a sample, K of them per pixel (row-major: pixel i's k-th at i * K + k).
class Strata {
 public:
  Strata(std::size_t figures, std::vector<std::uint32_t> block_size, std::vector<std::uint32_t> group,
         std::uint32_t groups);
  std::size_t figures() const { return k_; }
  std::size_t pixels() const { return block_size_.size(); }
  double& at(std::size_t pixel, std::size_t figure) {
    d_.clear();  // the deviations are computed again on the next variance
    return y_[pixel * k_ + figure];
  }
  double at(std::size_t pixel, std::size_t figure) const { return y_[pixel * k_ + figure]; }

  double sample_sum(std::size_t figure) const;  // sum of y over the sampled pixels
  double total(std::size_t figure) const;       // Horvitz-Thompson: sum of N_i y_i
  double variance(std::size_t figure) const;    // of total(figure), collapsed strata
  // The covariance matrix of the totals of `figures` (row-major, figures.size() squared).
  std::vector<double> covariance(const std::vector<std::size_t>& figures) const;
  // The covariance of a linear combination sum_k w_k total(k) (w over every figure) with each
  // of `figures`, and its own variance (last element): for a figure derived from the others.
  std::vector<double> covariance_with(const std::vector<double>& w, const std::vector<std::size_t>& figures) const;

 private:
  // Each pixel's T_i - (N_i / N_g) T_g for every figure, times sqrt(g / (g - 1)) (0 in a
  // group of one), computed once after the figures are set.
  const std::vector<double>& deviations() const;
  std::size_t k_;
  std::vector<std::uint32_t> block_size_, group_;
  std::uint32_t groups_;
  std::vector<double> y_;
  mutable std::vector<double> d_;
};

// Draws of a normal vector N(mean, cov) (cov row-major, positive semi-definite: a tiny ridge
// is added for the Cholesky factor), `draws` of them, from a generator seeded with `seed`
// (the same seed, the same draws on every machine: its own Box-Muller over splitmix64).
std::vector<std::vector<double>> normal_draws(const std::vector<double>& mean, const std::vector<double>& cov,
                                              std::size_t draws, std::uint64_t seed);

// The maximum of several estimated totals.
struct MaxEstimate {
  double plain = 0;       // max of the estimates
  double bias = 0;        // E[max of the draws] - plain
  double low = 0, high = 0;  // the basic bootstrap interval: 2 plain - the draws' 97.5 % and 2.5 % quantiles
  double estimate() const { return plain - bias; }
  std::size_t candidate = 0;  // the index (into the given totals) of the largest estimate
};
// `maxima` holds each draw's maximum; `plain` the maximum of the estimates.
MaxEstimate max_from_draws(std::vector<double> maxima, double plain, std::size_t candidate);

// The quantile q of x (linear interpolation between order statistics; x is reordered).
double quantile(std::vector<double>& x, double q);

}  // namespace oprt::sample
