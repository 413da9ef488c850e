#include "drivers/sim/bspline.h"

#include <cmath>
#include <stdexcept>

namespace kestrel::sim {
namespace {

double binomial(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

// Qin's closed form for order k = degree + 1:
// M_ij = C(k-1, i) / (k-1)! * sum_{s=j}^{k-1} (-1)^(s-j) C(k, s-j) (k-s-1)^(k-1-i).
std::array<std::array<double, PeriodicBSpline::kDegree + 1>, PeriodicBSpline::kDegree + 1> make_basis() {
  constexpr int k = PeriodicBSpline::kDegree + 1;
  double factorial = 1.0;
  for (int i = 2; i < k; ++i) factorial *= i;
  std::array<std::array<double, k>, k> m{};
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      double sum = 0.0;
      for (int s = j; s < k; ++s)
        sum += ((s - j) % 2 ? -1.0 : 1.0) * binomial(k, s - j) * std::pow(k - s - 1, k - 1 - i);
      m[i][j] = binomial(k - 1, i) / factorial * sum;
    }
  return m;
}

}  // namespace

PeriodicBSpline::PeriodicBSpline(std::vector<Eigen::Vector3d> control_points, double knot_dt_s)
    : points_(std::move(control_points)), knot_dt_s_(knot_dt_s) {
  if (points_.size() < kDegree + 1) throw std::invalid_argument("PeriodicBSpline: too few control points");
  if (!(knot_dt_s > 0)) throw std::invalid_argument("PeriodicBSpline: knot spacing must be > 0");
  period_s_ = knot_dt_s_ * static_cast<double>(points_.size());
}

const std::array<std::array<double, PeriodicBSpline::kDegree + 1>, PeriodicBSpline::kDegree + 1>&
PeriodicBSpline::basis() {
  static const auto m = make_basis();
  return m;
}

Eigen::Vector3d PeriodicBSpline::derivative(double t, int d) const {
  if (d < 0 || d > 3) throw std::invalid_argument("PeriodicBSpline: derivative order must be 0..3");
  const double s = t / knot_dt_s_;
  const double segment = std::floor(s);
  const double u = s - segment;
  const auto n = static_cast<int64_t>(points_.size());
  const int64_t first = ((static_cast<int64_t>(segment) % n) + n) % n;
  // d^d/du^d of u^i is i!/(i-d)! u^(i-d); dt = knot_dt du.
  std::array<double, kDegree + 1> powers{};
  for (int i = d; i <= kDegree; ++i) {
    double c = 1.0;
    for (int q = 0; q < d; ++q) c *= i - q;
    powers[i] = c * std::pow(u, i - d);
  }
  const auto& m = basis();
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int j = 0; j <= kDegree; ++j) {
    double w = 0.0;
    for (int i = d; i <= kDegree; ++i) w += powers[i] * m[i][j];
    out += w * points_[static_cast<size_t>((first + j) % n)];
  }
  return out / std::pow(knot_dt_s_, d);
}

}  // namespace kestrel::sim
