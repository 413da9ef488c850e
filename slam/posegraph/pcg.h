#pragma once
// Preconditioned conjugate gradients for a symmetric positive-definite system A x = b, where
// A and the preconditioner M^-1 are given as functions. Used to take Gauss-Newton steps with
// the factorisation of an earlier iteration as the preconditioner.

#include <Eigen/Core>

namespace kestrel::slam {

struct PcgResult {
  int iterations = 0;
  bool converged = false;  ///< |b - A x| <= tolerance * |b| within max_iterations
};

/// Starts from x = 0; on return x holds the last iterate.
template <class Multiply, class Precondition>
PcgResult pcg(const Multiply& A, const Precondition& M_inv, const Eigen::VectorXd& b,
              Eigen::VectorXd& x, int max_iterations, double tolerance) {
  PcgResult result;
  x.setZero(b.size());
  const double b_norm = b.norm();
  if (!(b_norm > 0.0)) {
    result.converged = true;
    return result;
  }
  Eigen::VectorXd r = b;
  Eigen::VectorXd z = M_inv(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  while (result.iterations < max_iterations) {
    ++result.iterations;
    const Eigen::VectorXd Ap = A(p);
    const double pAp = p.dot(Ap);
    if (!(pAp > 0.0)) break;  // not positive definite along p (or NaN): give up
    const double alpha = rz / pAp;
    x.noalias() += alpha * p;
    r.noalias() -= alpha * Ap;
    if (r.norm() <= tolerance * b_norm) {
      result.converged = true;
      break;
    }
    z = M_inv(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return result;
}

}  // namespace kestrel::slam
