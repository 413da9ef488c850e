// The information-form functions (information.h) and the sigma points behind them, checked
// on the planner's 4-dimensional belief (fixed size), the filter's 15-dimensional state and
// a 7-dimensional state (dynamic size): one harness, several dimensions.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/gaussian/information.h"
#include "common/gaussian/unscented.h"

namespace kestrel::gaussian {
namespace {

template <int N>
Mat<N> random_spd(std::mt19937& rng, int n = N) {
  std::normal_distribution<double> d(0.0, 1.0);
  Mat<N> A(n, n);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = d(rng);
  return A * A.transpose() + 0.1 * Mat<N>::Identity(n, n);
}

template <int R, int C>
Mat<R, C> random_matrix(std::mt19937& rng, int rows = R, int cols = C) {
  std::normal_distribution<double> d(0.0, 1.0);
  Mat<R, C> A(rows, cols);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = d(rng);
  return A;
}

template <class T>
class InformationForm : public ::testing::Test {};
// kN, kM: compile-time sizes; n, m: the sizes the test runs at. The filter's 15-dimensional
// case runs at dynamic size: every fixed-size instantiation costs about a minute of compile
// time, and the planner's fixed 4 x 3 already covers the fixed-size code paths.
template <int N, int M, int RuntimeN = N, int RuntimeM = M>
struct Dims {
  static constexpr int n = RuntimeN;
  static constexpr int m = RuntimeM;
  static constexpr int kN = N;
  static constexpr int kM = M;
};
using DimList = ::testing::Types<Dims<4, 3>, Dims<Eigen::Dynamic, Eigen::Dynamic, 15, 6>,
                                 Dims<Eigen::Dynamic, Eigen::Dynamic, 7, 3>>;
TYPED_TEST_SUITE(InformationForm, DimList);

TYPED_TEST(InformationForm, MeasurementInformationGivesTheKalmanPosterior) {
  constexpr int N = TypeParam::kN, M = TypeParam::kM;
  const int n = TypeParam::n, m = TypeParam::m;
  std::mt19937 rng(1);
  const Mat<N> Sigma = random_spd<N>(rng, n);
  const Mat<M, N> H = random_matrix<M, N>(rng, m, n);
  const Mat<M> Q = random_spd<M>(rng, m);
  // Kalman form.
  const Mat<M> S = H * Sigma * H.transpose() + Q;
  const Mat<N, M> K = Sigma * H.transpose() * S.inverse();
  const Mat<N> kalman = Sigma - K * H * Sigma;
  // Information form.
  const Mat<N> Minfo = measurement_information(H, Q);
  EXPECT_LT((Minfo - H.transpose() * Q.inverse() * H).norm(), 1e-9 * Minfo.norm());
  const Mat<N> via_information = (Sigma.inverse() + Minfo).inverse();
  const Mat<N> via_update = update_covariance(Sigma, Minfo);
  EXPECT_LT((via_information - kalman).norm(), 1e-9 * kalman.norm());
  EXPECT_LT((via_update - kalman).norm(), 1e-9 * kalman.norm());
}

TYPED_TEST(InformationForm, ProcessNoiseAndPrediction) {
  constexpr int N = TypeParam::kN;
  const int n = TypeParam::n;
  std::mt19937 rng(2);
  const Mat<N, Eigen::Dynamic> V = random_matrix<N, Eigen::Dynamic>(rng, n, 2);
  const Mat<Eigen::Dynamic> W = random_spd<Eigen::Dynamic>(rng, 2);
  const Mat<N> R = process_noise(V, W);
  EXPECT_LT((R - V * W * V.transpose()).norm(), 1e-12 * R.norm());
  EXPECT_EQ(R, R.transpose());
  const Eigen::Vector2d w(0.3, 2.0);
  EXPECT_LT((process_noise_diagonal(V, w) - V * w.asDiagonal() * V.transpose()).norm(), 1e-12);
  const Mat<N> G = random_matrix<N, N>(rng, n, n);
  const Mat<N> Sigma = random_spd<N>(rng, n);
  EXPECT_LT((predict_covariance(G, Sigma, R) - (G * Sigma * G.transpose() + R)).norm(),
            1e-9 * R.norm());
}

TYPED_TEST(InformationForm, UkfInformationEqualsEkfInformationForLinearMeasurements) {
  // For h(x) = H x the unscented transform is exact, so eq. 27 must give H^T Q^-1 H.
  constexpr int N = TypeParam::kN, M = TypeParam::kM;
  const int n = TypeParam::n, m = TypeParam::m;
  std::mt19937 rng(3);
  const Mat<N> Sigma = random_spd<N>(rng, n);
  const Mat<M, N> H = random_matrix<M, N>(rng, m, n);
  const Mat<M> Q = random_spd<M>(rng, m);
  const Eigen::Matrix<double, N, 1> mean = random_matrix<N, 1>(rng, n, 1);
  const auto h = [&](const Eigen::Matrix<double, N, 1>& x) -> Eigen::Matrix<double, M, 1> {
    return H * x;
  };
  for (const UnscentedParams p : {UnscentedParams{}, UnscentedParams{0.5, 2.0, 0.0}}) {
    const Mat<N> ukf = ukf_measurement_information(mean, Sigma, h, Q, p);
    const Mat<N> ekf = measurement_information(H, Q);
    EXPECT_LT((ukf - ekf).norm(), 1e-6 * ekf.norm()) << "alpha " << p.alpha;
  }
}

TEST(InformationForm, UkfInformationReproducesTheUkfPosteriorForARangeBearingSensor) {
  // The planner's use (the paper's Fig. 7): a range-bearing measurement of a landmark from
  // the (x, y, z, yaw) belief. Adding the M of eq. 27 to the prior information must give
  // exactly the UKF's own posterior covariance.
  const Eigen::Vector4d mean(1.0, 2.0, 1.5, 0.3);
  Eigen::Vector4d sd(0.3, 0.2, 0.1, 0.1);
  const Eigen::Matrix4d Sigma = sd.array().square().matrix().asDiagonal();
  const Eigen::Vector3d landmark(4.0, 3.0, 1.0);
  const auto h = [&](const Eigen::Vector4d& x) {
    const Eigen::Vector3d d = landmark - x.head<3>();
    double bearing = std::atan2(d.y(), d.x()) - x[3];
    return Eigen::Vector2d(d.norm(), bearing);
  };
  Eigen::Matrix2d Q = Eigen::Vector2d(0.05 * 0.05, 0.02 * 0.02).asDiagonal();
  const Eigen::Matrix4d M = ukf_measurement_information(mean, Sigma, h, Q);

  // The UKF update written out directly.
  const UnscentedWeights w = unscented_weights(4, {});
  const auto X = sigma_offsets(Sigma, w);
  Eigen::Vector2d z_bar = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> Z;
  for (int i = 0; i < 9; ++i) {
    Z.push_back(h(mean + X.col(i)));
    z_bar += (i == 0 ? w.mean0 : w.other) * Z.back();
  }
  Eigen::Matrix2d S = Q;
  Eigen::Matrix<double, 4, 2> C = Eigen::Matrix<double, 4, 2>::Zero();
  for (int i = 0; i < 9; ++i) {
    const double wc = i == 0 ? w.cov0 : w.other;
    S += wc * (Z[static_cast<size_t>(i)] - z_bar) * (Z[static_cast<size_t>(i)] - z_bar).transpose();
    C += wc * X.col(i) * (Z[static_cast<size_t>(i)] - z_bar).transpose();
  }
  const Eigen::Matrix4d posterior = Sigma - C * S.inverse() * C.transpose();
  EXPECT_LT((update_covariance(Sigma, M) - posterior).norm(), 1e-9 * posterior.norm());
  // And the information gained is real: the posterior is smaller.
  EXPECT_LT(posterior.trace(), 0.8 * Sigma.trace());
}

TEST(InformationForm, RejectsMatricesThatAreNotPositiveDefinite) {
  const Eigen::Matrix2d H = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d Q;
  Q << 1.0, 0.0, 0.0, -1.0;
  EXPECT_THROW(measurement_information(H, Q), std::invalid_argument);
  Q(1, 1) = std::nan("");
  EXPECT_THROW(measurement_information(H, Q), std::invalid_argument);
  EXPECT_THROW(update_covariance(Eigen::Matrix2d::Zero(), Eigen::Matrix2d::Identity()),
               std::invalid_argument);
  EXPECT_THROW(process_noise(Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Identity(2, 2)),
               std::invalid_argument);
}

TEST(Unscented, SquareRootOfASingularCovariance) {
  // A cloned pose makes the covariance exactly singular; the square root must still exist.
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  A.topLeftCorner<3, 3>() << 4, 1, 0, 1, 3, 0.5, 0, 0.5, 2;
  A.bottomRightCorner<3, 3>() = A.topLeftCorner<3, 3>();
  A.topRightCorner<3, 3>() = A.topLeftCorner<3, 3>();
  A.bottomLeftCorner<3, 3>() = A.topLeftCorner<3, 3>();
  const auto L = psd_square_root(A);
  EXPECT_LT((L * L.transpose() - A).norm(), 1e-12);
  Eigen::Matrix2d bad;
  bad << 1, 0, 0, -0.5;
  EXPECT_THROW(psd_square_root(bad), std::invalid_argument);
}

TEST(Unscented, SigmaPointsReproduceMeanAndCovariance) {
  std::mt19937 rng(4);
  const Mat<5> Sigma = random_spd<5>(rng);
  for (const UnscentedParams p : {UnscentedParams{}, UnscentedParams{0.3, 2.0, 1.0}}) {
    const UnscentedWeights w = unscented_weights(5, p);
    const auto X = sigma_offsets(Sigma, w);
    Eigen::Matrix<double, 5, 1> mean = w.mean0 * X.col(0);
    Mat<5> cov = w.cov0 * X.col(0) * X.col(0).transpose();
    for (int i = 1; i < 11; ++i) {
      mean += w.other * X.col(i);
      cov += w.other * X.col(i) * X.col(i).transpose();
    }
    EXPECT_LT(mean.norm(), 1e-12);
    EXPECT_LT((cov - Sigma).norm(), 1e-10 * Sigma.norm());
    EXPECT_NEAR(w.mean0 + 10 * w.other, 1.0, 1e-12);
  }
  EXPECT_THROW(unscented_weights(3, UnscentedParams{1.0, 0.0, -3.0}), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::gaussian
