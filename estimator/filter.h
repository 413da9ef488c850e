#pragma once
// The two filters behind one interface: the error-state EKF (the paper's Appendix A) and the
// error-state UKF (Appendix B). Both act on the same FilterState with the same IMU process
// model (propagation.h) and the same measurement models (measurements.h), so they are
// exchangeable in the estimator and comparable in tests.

#include <memory>

#include "estimator/filter_state.h"
#include "estimator/imu.h"
#include "estimator/measurements.h"
#include "estimator/propagation.h"
#include "common/gaussian/unscented.h"

namespace kestrel::estimator {

enum class FilterKind { kEkf, kUkf };

struct UpdateResult {
  bool applied = false;
  /// Squared Mahalanobis distance of the innovation, y^T S^-1 y (chi^2 with dim(y) dof).
  double mahalanobis2 = 0.0;
};

class Filter {
 public:
  virtual ~Filter() = default;
  virtual FilterKind kind() const = 0;
  /// Propagates mean and covariance over one IMU interval; mean.utime is the caller's.
  virtual void predict(FilterState& s, const ImuInterval& u) const = 0;
  /// Fuses one measurement; rejects it (state untouched) when gate_chi2 > 0 and the
  /// innovation's squared Mahalanobis distance exceeds it, or when S is not positive definite.
  virtual UpdateResult update(FilterState& s, const Measurement& m, double gate_chi2) const = 0;
};

class Ekf final : public Filter {
 public:
  Ekf(const ImuNoise& noise, double gravity) : noise_(noise), gravity_(gravity) {}
  FilterKind kind() const override { return FilterKind::kEkf; }
  void predict(FilterState& s, const ImuInterval& u) const override;
  UpdateResult update(FilterState& s, const Measurement& m, double gate_chi2) const override;

 private:
  ImuNoise noise_;
  double gravity_;
};

class Ukf final : public Filter {
 public:
  Ukf(const ImuNoise& noise, double gravity, const gaussian::UnscentedParams& params)
      : noise_(noise), gravity_(gravity), params_(params) {}
  FilterKind kind() const override { return FilterKind::kUkf; }
  void predict(FilterState& s, const ImuInterval& u) const override;
  UpdateResult update(FilterState& s, const Measurement& m, double gate_chi2) const override;

 private:
  ImuNoise noise_;
  double gravity_;
  gaussian::UnscentedParams params_;
};

std::unique_ptr<Filter> make_filter(FilterKind kind, const ImuNoise& noise, double gravity,
                                    const gaussian::UnscentedParams& params);

/// P <- Phi P Phi^T for a state whose first 15 entries are the navigation error (clones
/// after them do not move): Phi's block structure makes this O(n) 3x3 products, not O(n^3).
void transform_covariance(const Transition& phi, Covariance& P);

}  // namespace kestrel::estimator
