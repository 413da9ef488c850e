#pragma once
// Jacobians by central differences, the one way the tests check an analytic Jacobian.
//
// Every Jacobian in kestrel is a derivative with respect to a perturbation: of a vector
// (f(x + d)), or of a state on a manifold (f(x ⊞ d), measured as f(x ⊞ d) ⊟ f(x)). So the helper
// differentiates a function of the perturbation d at d = 0 and the caller writes how d enters:
//
//   const auto J = test::numerical_jacobian<3>([&](const Eigen::Vector3d& d) {
//     return so3::log(so3::exp(phi).transpose() * so3::exp(phi + d));
//   });
//
// Central differences err by O(h^2) times the third derivative, plus rounding of about
// eps * |g| / h: h = 1e-6 leaves ~1e-9 on functions of unit scale, so compare with tolerances
// of 1e-6 or looser.

#include <Eigen/Core>
#include <type_traits>

namespace kestrel::test {

/// dg/dd at d = 0 for g: R^n -> R^m (n = kIn, or `n` when kIn is Eigen::Dynamic); column k is
/// (g(h e_k) - g(-h e_k)) / 2h. g returns an Eigen vector (fixed or dynamic size).
template <int kIn, class G>
auto numerical_jacobian(const G& g, double h = 1e-6, Eigen::Index n = kIn) {
  using In = Eigen::Matrix<double, kIn, 1>;
  In d = In::Zero(n);
  using Out = typename std::decay_t<decltype(g(d).eval())>::PlainObject;
  // Sized from the first column: g is evaluated at ±h only, never at 0.
  Eigen::Matrix<double, Out::RowsAtCompileTime, kIn> J(Out::RowsAtCompileTime == Eigen::Dynamic ? 0 : Out::RowsAtCompileTime, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    d.setZero();
    d(k) = h;
    const Out plus = g(d);
    d(k) = -h;
    const Out minus = g(d);
    if (k == 0) J.resize(plus.size(), n);
    J.col(k) = (plus - minus) / (2.0 * h);
  }
  return J;
}

}  // namespace kestrel::test
