#pragma once
// Consistency of a filter against ground truth: the normalised estimation error squared
// (NEES, Bar-Shalom et al. 2001, §5.4) and its chi-square acceptance band for an average over
// Monte-Carlo runs. A consistent filter's NEES of a d-dimensional error is chi^2(d); the
// mean over N runs times N is chi^2(N d).

#include <Eigen/Core>
#include <vector>

#include "estimator/nav_state.h"

namespace kestrel::estimator {

/// e^T P^-1 e; P must be positive definite (throws std::invalid_argument otherwise).
double nees(const Eigen::VectorXd& error, const Eigen::MatrixXd& P);

/// The error of `estimate` against `truth` in the filter's error convention (truth ⊟
/// estimate), first 9 entries: [dp (world); dv (world); dtheta (body)].
Eigen::Matrix<double, 9, 1> pose_velocity_error(const NavState& truth, const NavState& estimate);

/// Quantile p of the standard normal distribution (Newton on erfc; |error| < 1e-12).
double normal_quantile(double p);
/// Quantile p of chi^2 with k degrees of freedom, exact to rounding (bisection on the
/// regularised incomplete gamma function); throws std::invalid_argument outside p in (0, 1), k > 0.
double chi2_quantile(double p, double k);

struct Band {
  double low = 0.0;
  double high = 0.0;
  bool contains(double v) const { return v >= low && v <= high; }
};
/// Two-sided band with probability `mass` for the mean NEES of `runs` runs of dimension `dim`.
Band mean_nees_band(int dim, int runs, double mass = 0.95);

/// NEES of many runs at common checkpoints (e.g. every 0.1 s of a flight): the mean over runs
/// at each checkpoint, tested against the 95 % band of that mean.
class NeesAccumulator {
 public:
  explicit NeesAccumulator(int dim) : dim_(dim) {}
  void add(size_t checkpoint, double value);

  struct Summary {
    double mean = 0.0;               ///< over all runs and checkpoints
    Band band;                       ///< of `mean` (all samples pooled, as if independent)
    double fraction_in_band = 0.0;   ///< checkpoints whose mean over runs is in its band
    size_t checkpoints = 0;
    int runs = 0;                    ///< at the first checkpoint
  };
  Summary summary(double mass = 0.95) const;
  /// Mean over runs at each checkpoint.
  std::vector<double> means() const;

 private:
  int dim_;
  std::vector<double> sum_;
  std::vector<int> count_;
};

}  // namespace kestrel::estimator
