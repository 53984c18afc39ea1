#include "sample/strata.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oprt::sample {

Strata::Strata(const double* y, std::size_t figures, const std::vector<std::uint32_t>& block_size,
               const std::vector<std::uint32_t>& group, std::uint32_t groups)
    : y_(y), k_(figures), block_size_(block_size), group_(group), groups_(groups), n_group_(groups, 0.0),
      factor_(groups, 0.0), sum_(figures, 0.0), total_(figures, 0.0), group_total_(groups * figures, 0.0) {
  if (group_.size() != block_size_.size()) throw std::invalid_argument("Strata: one group per pixel");
  std::vector<double> members(groups_, 0.0);
  for (std::size_t i = 0; i < pixels(); ++i) {  // one pass, row by row
    const std::uint32_t g = group_[i];
    if (g >= groups_) throw std::invalid_argument("Strata: group out of range");
    n_group_[g] += block_size_[i];
    members[g] += 1;
    const double* row = y_ + i * k_;
    double* tg = group_total_.data() + g * k_;
    for (std::size_t k = 0; k < k_; ++k) {
      sum_[k] += row[k];
      total_[k] += block_size_[i] * row[k];
      tg[k] += block_size_[i] * row[k];
    }
  }
  for (std::uint32_t g = 0; g < groups_; ++g)  // a group of one tells nothing of its variance
    factor_[g] = members[g] > 1 ? std::sqrt(members[g] / (members[g] - 1)) : 0.0;
  variance_.assign(k_, 0.0);
  for (std::size_t i = 0; i < pixels(); ++i) {  // every figure's variance, one more pass
    const std::uint32_t g = group_[i];
    if (factor_[g] == 0) continue;
    const double share = block_size_[i] / n_group_[g];
    const double* row = y_ + i * k_;
    const double* tg = group_total_.data() + g * k_;
    for (std::size_t k = 0; k < k_; ++k) {
      const double d = factor_[g] * (block_size_[i] * row[k] - share * tg[k]);
      variance_[k] += d * d;
    }
  }
}

template <typename Value, typename GroupTotal>
std::vector<double> Strata::deviations(Value&& value, GroupTotal&& group_total) const {
  std::vector<double> d(pixels());
  for (std::size_t i = 0; i < pixels(); ++i) {
    const std::uint32_t g = group_[i];
    if (factor_[g] != 0) d[i] = factor_[g] * (block_size_[i] * value(i) - block_size_[i] / n_group_[g] * group_total(g));
  }
  return d;
}

std::vector<double> Strata::figure_deviations(std::size_t k) const {
  return deviations([&](std::size_t i) { return at(i, k); }, [&](std::uint32_t g) { return group_total_[g * k_ + k]; });
}


std::vector<double> Strata::covariance(const std::vector<std::size_t>& figs) const {
  const std::size_t m = figs.size();
  std::vector<std::vector<double>> d;
  for (std::size_t f : figs) d.push_back(figure_deviations(f));
  std::vector<double> c(m * m, 0.0);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b <= a; ++b) {
      double s = 0;
      for (std::size_t i = 0; i < pixels(); ++i) s += d[a][i] * d[b][i];
      c[a * m + b] = c[b * m + a] = s;
    }
  return c;
}

std::vector<double> Strata::covariance_with(const std::vector<double>& w, const std::vector<std::size_t>& figs) const {
  if (w.size() != k_) throw std::invalid_argument("Strata::covariance_with: one weight per figure");
  std::vector<std::size_t> used;  // the figures with a weight
  for (std::size_t k = 0; k < k_; ++k)
    if (w[k] != 0) used.push_back(k);
  const auto combined = [&](const double* row) {
    double s = 0;
    for (std::size_t k : used) s += w[k] * row[k];
    return s;
  };
  const std::vector<double> lin = deviations([&](std::size_t i) { return combined(y_ + i * k_); },
                                             [&](std::uint32_t g) { return combined(group_total_.data() + g * k_); });
  std::vector<double> c(figs.size() + 1, 0.0);
  for (std::size_t a = 0; a < figs.size(); ++a) {
    const std::vector<double> d = figure_deviations(figs[a]);
    for (std::size_t i = 0; i < pixels(); ++i) c[a] += lin[i] * d[i];
  }
  for (double x : lin) c.back() += x * x;
  return c;
}

double Strata::series_total(const std::vector<double>& v) const {
  double s = 0;
  for (std::size_t i = 0; i < pixels(); ++i) s += block_size_[i] * v[i];
  return s;
}

double Strata::series_variance(const std::vector<double>& v) const {
  std::vector<double> tg(groups_, 0.0);
  for (std::size_t i = 0; i < pixels(); ++i) tg[group_[i]] += block_size_[i] * v[i];
  double s = 0;
  for (double x : deviations([&](std::size_t i) { return v[i]; }, [&](std::uint32_t g) { return tg[g]; })) s += x * x;
  return s;
}

namespace {
std::uint64_t splitmix(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double uniform(std::uint64_t& s) { return (static_cast<double>(splitmix(s) >> 11) + 0.5) * 0x1.0p-53; }  // (0, 1)
}  // namespace

std::vector<std::vector<double>> normal_draws(const std::vector<double>& mean, const std::vector<double>& cov,
                                              std::size_t draws, std::uint64_t seed) {
  const std::size_t m = mean.size();
  if (cov.size() != m * m) throw std::invalid_argument("normal_draws: covariance size");
  // The Cholesky factor of the correlation matrix (coordinates of any scale: cycles and joules
  // side by side), with a ridge of 1e-12 for an estimate that is only semi-definite; a
  // coordinate without variance stays at its mean.
  std::vector<double> sd(m), l(m * m, 0.0);
  for (std::size_t a = 0; a < m; ++a) sd[a] = cov[a * m + a] > 0 ? std::sqrt(cov[a * m + a]) : 0.0;
  const auto corr = [&](std::size_t a, std::size_t b) {
    if (sd[a] == 0 || sd[b] == 0) return a == b ? 1.0 : 0.0;
    return a == b ? 1.0 + 1e-12 : cov[a * m + b] / (sd[a] * sd[b]);
  };
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b <= a; ++b) {
      double s = corr(a, b);
      for (std::size_t k = 0; k < b; ++k) s -= l[a * m + k] * l[b * m + k];
      if (a == b) l[a * m + a] = s > 0 ? std::sqrt(s) : 0.0;
      else l[a * m + b] = l[b * m + b] > 0 ? s / l[b * m + b] : 0.0;
    }
  std::uint64_t state = seed;
  std::vector<std::vector<double>> out(draws, std::vector<double>(m));
  std::vector<double> z(m);
  for (auto& x : out) {
    for (std::size_t a = 0; a < m; a += 2) {  // Box-Muller: two normals from two uniforms
      const double r = std::sqrt(-2 * std::log(uniform(state))), t = 2 * M_PI * uniform(state);
      z[a] = r * std::cos(t);
      if (a + 1 < m) z[a + 1] = r * std::sin(t);
    }
    for (std::size_t a = 0; a < m; ++a) {
      double v = 0;
      for (std::size_t b = 0; b <= a; ++b) v += l[a * m + b] * z[b];
      x[a] = mean[a] + sd[a] * v;
    }
  }
  return out;
}

double quantile(std::vector<double>& x, double q) {
  if (x.empty()) return 0;
  std::sort(x.begin(), x.end());
  const double pos = q * static_cast<double>(x.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  if (i + 1 >= x.size()) return x.back();
  return x[i] + (pos - static_cast<double>(i)) * (x[i + 1] - x[i]);
}

MaxEstimate max_from_draws(std::vector<double> maxima, double plain, std::size_t candidate) {
  MaxEstimate e;
  e.plain = plain;
  e.candidate = candidate;
  if (maxima.empty()) {
    e.low = e.high = plain;
    return e;
  }
  double mean = 0;
  for (double v : maxima) mean += v;
  mean /= static_cast<double>(maxima.size());
  e.bias = mean - plain;
  // The basic bootstrap interval: the draws' spread around their mean, reflected about the
  // estimate (a maximum's distribution is skewed to the right; the truth lies to the left).
  e.low = 2 * plain - quantile(maxima, (1 + kConfidence) / 2);
  e.high = 2 * plain - quantile(maxima, (1 - kConfidence) / 2);
  return e;
}

}  // namespace oprt::sample
