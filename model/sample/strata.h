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
// upward when several are close: E[max X] >= max E[X]. max_from_draws takes draws of the
// totals from the normal distribution with the estimated covariance (normal_draws) and
// returns the bias and a basic bootstrap interval of the maximum (its distribution is skewed
// when totals are close).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace oprt::sample {

constexpr double kConfidence = 0.95;
constexpr double kZ95 = 1.959963984540054;  // the normal distribution's 97.5 % quantile

// A sample's per-pixel figures, K of them per pixel (pixel i's k-th at y[i * K + k]), read in
// place: the figures, the block sizes and the groups must outlive the Strata.
class Strata {
 public:
  Strata(const double* y, std::size_t figures, const std::vector<std::uint32_t>& block_size,
         const std::vector<std::uint32_t>& group, std::uint32_t groups);
  std::size_t figures() const { return k_; }
  std::size_t pixels() const { return block_size_.size(); }
  double at(std::size_t pixel, std::size_t figure) const { return y_[pixel * k_ + figure]; }

  double sample_sum(std::size_t figure) const { return sum_[figure]; }  // sum of y over the sampled pixels
  double total(std::size_t figure) const { return total_[figure]; }     // Horvitz-Thompson: sum of N_i y_i
  double variance(std::size_t figure) const { return variance_[figure]; }  // of total(figure), collapsed strata
  // The covariance matrix of the totals of `figures` (row-major, figures.size() squared).
  std::vector<double> covariance(const std::vector<std::size_t>& figures) const;
  // For a linear combination sum_k w_k total(k) (w over every figure): its covariance with
  // each of `figures`, and its own variance (last element).
  std::vector<double> covariance_with(const std::vector<double>& w, const std::vector<std::size_t>& figures) const;
  // The same for any per-pixel series v (one value per pixel): its total and its variance.
  double series_total(const std::vector<double>& v) const;
  double series_variance(const std::vector<double>& v) const;

 private:
  // Each pixel's T_i - (N_i / N_g) T_g of the series value(i), times sqrt(g / (g - 1)) (0 in
  // a group of one): the variance is the sum of their squares. `group_total(g)`: the series' T_g.
  template <typename Value, typename GroupTotal>
  std::vector<double> deviations(Value&& value, GroupTotal&& group_total) const;
  std::vector<double> figure_deviations(std::size_t k) const;
  const double* y_;
  std::size_t k_;
  const std::vector<std::uint32_t>& block_size_;
  const std::vector<std::uint32_t>& group_;
  std::uint32_t groups_;
  std::vector<double> n_group_, factor_;  // per group: its pixels N_g and sqrt(g / (g - 1)), 0 for one
  std::vector<double> sum_, total_, group_total_, variance_;  // per figure; [group * K + figure]: T_g
};

// Draws of a normal vector N(mean, cov) (cov row-major, positive semi-definite), `draws` of
// them, from a generator seeded with `seed` (the same seed, the same draws on every machine:
// its own Box-Muller over splitmix64).
std::vector<std::vector<double>> normal_draws(const std::vector<double>& mean, const std::vector<double>& cov,
                                              std::size_t draws, std::uint64_t seed);

// The maximum of several estimated totals.
struct MaxEstimate {
  double plain = 0;          // max of the estimates
  double bias = 0;           // E[max of the draws] - plain
  double low = 0, high = 0;  // the basic bootstrap interval: 2 plain - the draws' 97.5 % and 2.5 % quantiles
  std::size_t candidate = 0;  // the index (into the given totals) of the largest estimate
  double estimate() const { return plain - bias; }
};
// `maxima` holds each draw's maximum; `plain` the maximum of the estimates.
MaxEstimate max_from_draws(std::vector<double> maxima, double plain, std::size_t candidate);

// The quantile q of x (linear interpolation between order statistics; x is reordered).
double quantile(std::vector<double>& x, double q);

}  // namespace oprt::sample
