#pragma once
// A periodic uniform quintic B-spline in R^3: the smooth closed curve of the spline flights.
//
// Control points P_0..P_{n-1} wrap around (P_n = P_0), knots are `knot_dt_s` apart, and the
// curve is periodic with period n * knot_dt_s. Degree 5 makes the curve C4: position,
// velocity, acceleration, jerk and snap are continuous, so a vehicle that follows it (whose
// attitude depends on acceleration and whose angular rate depends on jerk) has a continuous
// angular rate. The curve stays within the convex hull of six consecutive control points.
// Evaluation uses the matrix form of Qin (2000), "General matrix representations for
// B-splines": value = [1 u u^2 ... u^5] M [P_i ... P_{i+5}]^T with u in [0, 1).

#include <Eigen/Core>
#include <array>
#include <vector>

namespace kestrel::sim {

class PeriodicBSpline {
 public:
  static constexpr int kDegree = 5;

  /// Needs at least kDegree + 1 control points and knot_dt_s > 0 (std::invalid_argument).
  PeriodicBSpline(std::vector<Eigen::Vector3d> control_points, double knot_dt_s);

  /// The d-th time derivative (d = 0..3) of the curve at t (any real t; the curve repeats).
  Eigen::Vector3d derivative(double t, int d) const;
  Eigen::Vector3d position(double t) const { return derivative(t, 0); }

  double period_s() const { return period_s_; }
  const std::vector<Eigen::Vector3d>& control_points() const { return points_; }

  /// The basis matrix M (row i: coefficient of u^i, column j: weight of P_{i+j}).
  static const std::array<std::array<double, kDegree + 1>, kDegree + 1>& basis();

 private:
  std::vector<Eigen::Vector3d> points_;
  double knot_dt_s_;
  double period_s_;
};

}  // namespace kestrel::sim
