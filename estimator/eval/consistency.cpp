#include "estimator/eval/consistency.h"

#include "common/numbers.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::estimator {

double nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& P) {
  const Eigen::LLT<Eigen::MatrixXd> llt(P);
  if (llt.info() != Eigen::Success || P.rows() != error.size())
    throw std::invalid_argument("nees: P is not positive definite or of the wrong size");
  return error.dot(llt.solve(error));
}

Eigen::Matrix<double, 9, 1> pose_velocity_error(const NavState& truth, const NavState& estimate) {
  return boxminus(truth, estimate).head<9>();
}

double normal_quantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("normal_quantile: p must be in (0, 1)");
  double z = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * kPi);
    const double step = (cdf - p) / pdf;
    z -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return z;
}

namespace {

// Regularised lower incomplete gamma P(a, x): its power series where that converges fast
// (x < a + 1), else 1 - Q(a, x) with Q from its continued fraction (modified Lentz).
double regularized_gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefactor = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000 && std::abs(term) > 1e-17 * std::abs(sum); ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return sum * std::exp(log_prefactor);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int n = 1; n < 10000; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefactor) * h;
}

}  // namespace

double chi2_quantile(double p, double k) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("chi2_quantile: p must be in (0, 1)");
  if (!(k > 0.0)) throw std::invalid_argument("chi2_quantile: k must be > 0");
  // Wilson-Hilferty gives a bracket's first guess; bisection on the exact CDF (P(k/2, x/2))
  // then converges to rounding, whatever k: the NEES bands must not depend on an approximation.
  const double z = normal_quantile(p);
  const double a = 2.0 / (9.0 * k);
  const double c = std::max(1e-3, 1.0 - a + z * std::sqrt(a));
  double guess = k * c * c * c;
  double low = 0.0, high = std::max(guess, 1.0);
  while (regularized_gamma_p(0.5 * k, 0.5 * high) < p) high *= 2.0;
  for (int i = 0; i < 200 && high - low > 1e-13 * high; ++i) {
    const double mid = 0.5 * (low + high);
    (regularized_gamma_p(0.5 * k, 0.5 * mid) < p ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

Band mean_nees_band(int dim, int runs, double mass) {
  const double k = static_cast<double>(dim) * runs;
  const double tail = 0.5 * (1.0 - mass);
  return {chi2_quantile(tail, k) / runs, chi2_quantile(1.0 - tail, k) / runs};
}

void NeesAccumulator::add(size_t checkpoint, double value) {
  if (checkpoint >= sum_.size()) {
    sum_.resize(checkpoint + 1, 0.0);
    count_.resize(checkpoint + 1, 0);
  }
  sum_[checkpoint] += value;
  ++count_[checkpoint];
}

std::vector<double> NeesAccumulator::means() const {
  std::vector<double> m(sum_.size(), 0.0);
  for (size_t i = 0; i < sum_.size(); ++i)
    if (count_[i] > 0) m[i] = sum_[i] / count_[i];
  return m;
}

NeesAccumulator::Summary NeesAccumulator::summary(double mass) const {
  Summary s;
  double total = 0.0;
  long samples = 0;
  size_t inside = 0;
  for (size_t i = 0; i < sum_.size(); ++i) {
    if (count_[i] == 0) continue;
    ++s.checkpoints;
    total += sum_[i];
    samples += count_[i];
    if (mean_nees_band(dim_, count_[i], mass).contains(sum_[i] / count_[i])) ++inside;
  }
  if (samples == 0) return s;
  s.runs = count_.empty() ? 0 : count_[0];
  s.mean = total / static_cast<double>(samples);
  s.band = mean_nees_band(dim_, static_cast<int>(samples), mass);
  s.fraction_in_band = static_cast<double>(inside) / static_cast<double>(s.checkpoints);
  return s;
}

}  // namespace kestrel::estimator
