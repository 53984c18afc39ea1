#include "sample/strata.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace oprt::sample {

Strata::Strata(std::size_t figures, std::vector<std::uint32_t> block_size, std::vector<std::uint32_t> group,
               std::uint32_t groups)
    : k_(figures), block_size_(std::move(block_size)), group_(std::move(group)), groups_(groups),
      y_(k_ * block_size_.size(), 0.0) {
  if (group_.size() != block_size_.size()) throw std::invalid_argument("Strata: one group per pixel");
  for (std::uint32_t g : group_)
    if (g >= groups_) throw std::invalid_argument("Strata: group out of range");
}

double Strata::sample_sum(std::size_t k) const {
  double s = 0;
  for (std::size_t i = 0; i < pixels(); ++i) s += at(i, k);
  return s;
}

double Strata::total(std::size_t k) const {
  double s = 0;
  for (std::size_t i = 0; i < pixels(); ++i) s += block_size_[i] * at(i, k);
  return s;
}

template <typename F>
void Strata::deviations(F&& f) const {
  std::vector<double> tg(groups_ * k_, 0.0), ng(groups_, 0.0), members(groups_, 0.0);
  for (std::size_t i = 0; i < pixels(); ++i) {
    const std::uint32_t g = group_[i];
    ng[g] += block_size_[i];
    members[g] += 1;
    for (std::size_t k = 0; k < k_; ++k) tg[g * k_ + k] += block_size_[i] * at(i, k);
  }
  std::vector<double> d(k_);
  for (std::size_t i = 0; i < pixels(); ++i) {
    const std::uint32_t g = group_[i];
    if (members[g] < 2) continue;  // a group of one tells nothing of its variance
    const double share = block_size_[i] / ng[g];
    for (std::size_t k = 0; k < k_; ++k) d[k] = block_size_[i] * at(i, k) - share * tg[g * k_ + k];
    f(d, members[g] / (members[g] - 1));
  }
}

double Strata::variance(std::size_t k) const {
  double v = 0;
  deviations([&](const std::vector<double>& d, double factor) { v += factor * d[k] * d[k]; });
  return v;
}

std::vector<double> Strata::covariance(const std::vector<std::size_t>& figs) const {
  const std::size_t m = figs.size();
  std::vector<double> c(m * m, 0.0);
  deviations([&](const std::vector<double>& d, double factor) {
    for (std::size_t a = 0; a < m; ++a)
      for (std::size_t b = 0; b <= a; ++b) c[a * m + b] += factor * d[figs[a]] * d[figs[b]];
  });
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < a; ++b) c[b * m + a] = c[a * m + b];
  return c;
}

std::vector<double> Strata::covariance_with(const std::vector<double>& w, const std::vector<std::size_t>& figs) const {
  if (w.size() != k_) throw std::invalid_argument("Strata::covariance_with: one weight per figure");
  std::vector<double> c(figs.size() + 1, 0.0);
  deviations([&](const std::vector<double>& d, double factor) {
    double lin = 0;
    for (std::size_t k = 0; k < k_; ++k) lin += w[k] * d[k];
    for (std::size_t a = 0; a < figs.size(); ++a) c[a] += factor * lin * d[figs[a]];
    c.back() += factor * lin * lin;
  });
  return c;
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
  // Cholesky with a ridge of 1e-12 of the largest variance (a semi-definite estimate).
  double scale = 0;
  for (std::size_t a = 0; a < m; ++a) scale = std::max(scale, cov[a * m + a]);
  std::vector<double> l(m * m, 0.0);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b <= a; ++b) {
      double s = cov[a * m + b] + (a == b ? 1e-12 * scale : 0.0);
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
      double v = mean[a];
      for (std::size_t b = 0; b <= a; ++b) v += l[a * m + b] * z[b];
      x[a] = v;
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
