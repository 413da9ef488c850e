// The filters' states as manifolds (test/support/manifold_laws.h): the navigation state's
// boxplus / boxminus (nav_state.h) and the whole filter mean's with three clones
// (filter_state.h), with the rotation of every block perturbed on the right.

#include <gtest/gtest.h>

#include <random>

#include "common/geometry/so3.h"
#include "estimator/filter_state.h"
#include "estimator/nav_state.h"
#include "test/support/manifold_laws.h"

namespace kestrel::estimator {
namespace {

Eigen::Vector3d gaussian3(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

// Appends a block's coordinates to an embedding filled from `at`.
template <int kRows>
void append(Eigen::VectorXd& v, Eigen::Index& at, const Eigen::Matrix<double, kRows, 1>& x) {
  v.segment<kRows>(at) = x;
  at += kRows;
}

NavState sample_nav(std::mt19937& rng) {
  NavState x;
  x.p_world_body = gaussian3(rng, 2.0);
  x.v_world_body = gaussian3(rng, 1.0);
  x.R_world_body = so3::exp(gaussian3(rng, 1.0));
  x.gyro_bias = gaussian3(rng, 0.02);
  x.accel_bias = gaussian3(rng, 0.1);
  return x;
}

struct NavStateModel {
  using Point = NavState;
  static constexpr int kDim = idx::kNav;
  static constexpr double kChartRadius = 3.1;  // the rotation block below pi
  static Point sample(std::mt19937& rng) { return sample_nav(rng); }
  static Point plus(const Point& x, const Vector15d& d) { return boxplus(x, d); }
  static Vector15d minus(const Point& y, const Point& x) { return boxminus(y, x); }
  static Eigen::VectorXd embed(const Point& x) {
    Eigen::VectorXd v(21);
    Eigen::Index at = 0;
    append(v, at, x.p_world_body);
    append(v, at, x.v_world_body);
    append(v, at, test::embed_rotation(x.R_world_body));
    append(v, at, x.gyro_bias);
    append(v, at, x.accel_bias);
    return v;
  }
  static bool valid(const Point& x) { return x.all_finite() && so3::is_valid(x.R_world_body, test::kLawTolerance); }
};

struct FilterMeanModel {
  using Point = FilterMean;
  static constexpr int kDim = kMaxDim;  // all three clones held
  static constexpr double kChartRadius = 3.1;
  static Point sample(std::mt19937& rng) {
    FilterMean x;
    x.utime = 5'000'000;
    x.nav = sample_nav(rng);
    x.num_clones = kMaxClones;
    for (int i = 0; i < kMaxClones; ++i) {
      Clone& c = x.clones[static_cast<size_t>(i)];
      c.utime = 1'000'000 * (i + 1);
      c.p_world_body = gaussian3(rng, 2.0);
      c.R_world_body = so3::exp(gaussian3(rng, 1.0));
    }
    return x;
  }
  static Point plus(const Point& x, const Eigen::Matrix<double, kDim, 1>& d) { return boxplus(x, ErrorVector(d)); }
  static Eigen::Matrix<double, kDim, 1> minus(const Point& y, const Point& x) { return boxminus(y, x); }
  static Eigen::VectorXd embed(const Point& x) {
    Eigen::VectorXd v(21 + 12 * kMaxClones);
    v.head<21>() = NavStateModel::embed(x.nav);
    Eigen::Index at = 21;
    for (int i = 0; i < x.num_clones; ++i) {
      const Clone& c = x.clones[static_cast<size_t>(i)];
      append(v, at, c.p_world_body);
      append(v, at, test::embed_rotation(c.R_world_body));
    }
    return v;
  }
  static bool valid(const Point& x) {
    if (!NavStateModel::valid(x.nav)) return false;
    for (int i = 0; i < x.num_clones; ++i) {
      const Clone& c = x.clones[static_cast<size_t>(i)];
      if (!c.p_world_body.allFinite() || !so3::is_valid(c.R_world_body, test::kLawTolerance)) return false;
    }
    return true;
  }
};

using namespace ::kestrel::test;  // the suites' names, as INSTANTIATE_TYPED_TEST_SUITE_P needs them
using EstimatorStates = ::testing::Types<NavStateModel, FilterMeanModel>;
INSTANTIATE_TYPED_TEST_SUITE_P(Estimator, ManifoldLaws, EstimatorStates);

}  // namespace
}  // namespace kestrel::estimator
