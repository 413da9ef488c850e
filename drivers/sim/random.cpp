#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

// Standard normal CDF.
double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Inverse of normal_cdf by bisection: slow, but only used to build the table once.
double normal_quantile(double p) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (normal_cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

NormalTable::NormalTable() {
  const size_t n = values_.size();
  double sum_sq = 0.0;
  std::array<double, 1u << kBits> q{};
  for (size_t i = 0; i < n; ++i) {
    q[i] = normal_quantile((static_cast<double>(i) + 0.5) / static_cast<double>(n));
    sum_sq += q[i] * q[i];
  }
  // Binning shortens the tails a little; rescale so the variance is exactly one.
  const double scale = 1.0 / std::sqrt(sum_sq / static_cast<double>(n));
  for (size_t i = 0; i < n; ++i) values_[i] = static_cast<float>(q[i] * scale);
}

const NormalTable& normal_table() {
  static const NormalTable table;
  return table;
}

}  // namespace kestrel::sim
