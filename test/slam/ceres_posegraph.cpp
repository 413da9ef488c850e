#include "test/slam/ceres_posegraph.h"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <ctime>
#include <vector>

#include "common/geometry/se3.h"
#include "common/numbers.h"

namespace kestrel::slam::test {
namespace {

// S with S^T S = Omega (Omega positive semi-definite).
template <int N>
Eigen::Matrix<double, N, N> square_root(const Eigen::Matrix<double, N, N>& omega) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(omega);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
}

template <class T>
T wrap(const T& a) {
  const T two_pi(2.0 * kPi);
  return a - two_pi * ceres::floor((a + T(kPi)) / two_pi);
}

struct Se2Error {
  Eigen::Vector3d z_inv;  // x, y, theta of Z^-1
  Eigen::Matrix3d sqrt_information;
  template <class T>
  bool operator()(const T* xi, const T* xj, T* residual) const {
    // Delta = Xi^-1 Xj, then E = Z^-1 Delta.
    const T ci = ceres::cos(xi[2]), si = ceres::sin(xi[2]);
    const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
    const T tdx = ci * dx + si * dy, tdy = -si * dx + ci * dy;
    const T cz(std::cos(z_inv.z())), sz(std::sin(z_inv.z()));
    Eigen::Matrix<T, 3, 1> e;
    e(0) = cz * tdx - sz * tdy + T(z_inv.x());
    e(1) = sz * tdx + cz * tdy + T(z_inv.y());
    e(2) = wrap(T(z_inv.z()) + xj[2] - xi[2]);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information.cast<T>() * e;
    return true;
  }
};

struct Se3Error {
  Eigen::Quaterniond q_z_inv;
  Eigen::Vector3d t_z_inv;
  Eigen::Matrix<double, 6, 6> sqrt_information;
  template <class T>
  bool operator()(const T* pi, const T* qi, const T* pj, const T* qj, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> ti(pi), tj(pj);
    const Eigen::Map<const Eigen::Quaternion<T>> Qi(qi), Qj(qj);
    const Eigen::Quaternion<T> Qi_inv = Qi.conjugate();
    const Eigen::Quaternion<T> qz = q_z_inv.cast<T>();
    const Eigen::Quaternion<T> qE = qz * (Qi_inv * Qj);
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = qz * (Qi_inv * (tj - ti)) + t_z_inv.cast<T>();
    const T sign = qE.w() < T(0) ? T(-1) : T(1);
    e.template tail<3>() = sign * qE.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_information.cast<T>() * e;
    return true;
  }
};

ceres::Solver::Options options(int max_iterations) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.num_threads = 1;
  o.max_num_iterations = max_iterations;
  o.logging_type = ceres::SILENT;
  return o;
}

CeresResult result(const ceres::Solver::Summary& s) {
  CeresResult r;
  r.iterations = s.num_successful_steps + s.num_unsuccessful_steps;
  r.converged = s.termination_type == ceres::CONVERGENCE;
  return r;
}

template <class Graph>
int anchor(const Graph& graph) {
  for (int v = 0; v < graph.num_vertices(); ++v) {
    if (graph.fixed[v]) return v;
  }
  return 0;
}

}  // namespace

CeresResult ceres_optimize(PoseGraph2d& graph, int max_iterations) {
  std::vector<Eigen::Vector3d> x(graph.poses.begin(), graph.poses.end());
  ceres::Problem problem;
  for (const auto& e : graph.edges) {
    auto* cost = new ceres::AutoDiffCostFunction<Se2Error, 3, 3, 3>(
        new Se2Error{Se2::inverse(e.measurement), square_root<3>(e.information)});
    problem.AddResidualBlock(cost, nullptr, x[e.from].data(), x[e.to].data());
  }
  const int first = anchor(graph);
  for (int v = 0; v < graph.num_vertices(); ++v) {
    if ((graph.fixed[v] || v == first) && problem.HasParameterBlock(x[v].data())) {
      problem.SetParameterBlockConstant(x[v].data());
    }
  }
  ceres::Solver::Summary summary;
  const std::clock_t start = std::clock();
  ceres::Solve(options(max_iterations), &problem, &summary);
  const std::clock_t stop = std::clock();
  for (int v = 0; v < graph.num_vertices(); ++v) {
    graph.poses[v] = Se2::Pose(x[v].x(), x[v].y(), wrap_angle(x[v].z()));
  }
  CeresResult r = result(summary);
  r.final_chi2 = chi2(graph);
  r.solve_seconds = static_cast<double>(stop - start) / CLOCKS_PER_SEC;
  return r;
}

CeresResult ceres_optimize(PoseGraph3d& graph, int max_iterations) {
  const int n = graph.num_vertices();
  std::vector<Eigen::Vector3d> t(n);
  std::vector<Eigen::Quaterniond> q(n);
  for (int v = 0; v < n; ++v) {
    t[v] = graph.poses[v].translation();
    q[v] = Eigen::Quaterniond(graph.poses[v].linear()).normalized();
  }
  ceres::Problem problem;
  auto* manifold = new ceres::EigenQuaternionManifold;  // owned by the problem
  for (const auto& e : graph.edges) {
    const Se3::Pose z_inv = Se3::inverse(e.measurement);
    auto* cost = new ceres::AutoDiffCostFunction<Se3Error, 6, 3, 4, 3, 4>(new Se3Error{
        Eigen::Quaterniond(z_inv.linear()), z_inv.translation(), square_root<6>(e.information)});
    problem.AddResidualBlock(cost, nullptr, t[e.from].data(), q[e.from].coeffs().data(),
                             t[e.to].data(), q[e.to].coeffs().data());
  }
  const int first = anchor(graph);
  for (int v = 0; v < n; ++v) {
    if (!problem.HasParameterBlock(q[v].coeffs().data())) continue;
    problem.SetManifold(q[v].coeffs().data(), manifold);
    if (graph.fixed[v] || v == first) {
      problem.SetParameterBlockConstant(t[v].data());
      problem.SetParameterBlockConstant(q[v].coeffs().data());
    }
  }
  ceres::Solver::Summary summary;
  const std::clock_t start = std::clock();
  ceres::Solve(options(max_iterations), &problem, &summary);
  const std::clock_t stop = std::clock();
  for (int v = 0; v < n; ++v) graph.poses[v] = se3::make(q[v], t[v]);
  CeresResult r = result(summary);
  r.final_chi2 = chi2(graph);
  r.solve_seconds = static_cast<double>(stop - start) / CLOCKS_PER_SEC;
  return r;
}

}  // namespace kestrel::slam::test
