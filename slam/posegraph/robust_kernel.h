#pragma once
// Robust kernels rho(s) of the squared Mahalanobis error s = e^T Omega e, against loop
// closures that are wrong. The solver minimises sum rho(s_k) by iteratively re-weighted
// least squares: each edge enters the normal equations weighted by rho'(s_k).
//
// `width` is in units of the error's standard deviation (s = width^2 is where the kernel starts
// to depart from plain least squares). All kernels satisfy rho(0) = 0, rho'(0) = 1.

#include <cmath>
#include <string>

namespace kestrel::slam {

enum class KernelType { kNone, kHuber, kCauchy, kDcs };

struct RobustKernel {
  KernelType type = KernelType::kNone;
  double width = 3.0;

  /// rho(s).
  double cost(double s) const {
    const double d2 = width * width;
    switch (type) {
      case KernelType::kNone: return s;
      case KernelType::kHuber: return s <= d2 ? s : 2.0 * width * std::sqrt(s) - d2;
      case KernelType::kCauchy: return d2 * std::log1p(s / d2);
      // Dynamic covariance scaling (Agarwal et al., ICRA 2013): bounded by 3 width^2.
      case KernelType::kDcs: return s <= d2 ? s : d2 * (3.0 * s - d2) / (s + d2);
    }
    return s;
  }
  /// rho'(s), the weight of the edge in the normal equations.
  double weight(double s) const {
    const double d2 = width * width;
    switch (type) {
      case KernelType::kNone: return 1.0;
      case KernelType::kHuber: return s <= d2 ? 1.0 : width / std::sqrt(s);
      case KernelType::kCauchy: return 1.0 / (1.0 + s / d2);
      case KernelType::kDcs: return s <= d2 ? 1.0 : 4.0 * d2 * d2 / ((s + d2) * (s + d2));
    }
    return 1.0;
  }
};

/// "none", "huber", "cauchy", "dcs" (throws std::invalid_argument otherwise).
KernelType parse_kernel_type(const std::string& name);
const char* kernel_type_name(KernelType type);

}  // namespace kestrel::slam
