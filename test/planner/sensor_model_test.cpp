// The feature sensor: visibility rules, analytic Jacobians, and M against its definition.
#include <gtest/gtest.h>

#include "common/numbers.h"
#include "common/gaussian/information.h"
#include "planner/grid_environment.h"
#include "planner/sensor_model.h"
#include "test/support/numerical.h"
#include "test_environments.h"

namespace kestrel::planner {
namespace {

using testing::PredicateEnvironment;

PredicateEnvironment open_space() {
  return PredicateEnvironment({Eigen::Vector3d(-10, -10, 0), Eigen::Vector3d(10, 10, 3)},
                              [](const Eigen::Vector3d&) { return true; });
}

Feature feature(double x, double y, double z, Eigen::Vector3d normal) {
  Feature f;
  f.position = {x, y, z};
  f.normal = normal.normalized();
  return f;
}

TEST(FeatureSensor, SeesOnlyFeaturesInRangeInViewAndFacingIt) {
  PredicateEnvironment env = open_space();
  const Eigen::Vector3d towards(-1, 0, 0);
  env.set_features({feature(1.5, 0, 1, towards),      // ahead, 1.5 m: seen
                    feature(2.5, 0, 1, towards),      // beyond 2 m
                    feature(1.5, 0.6, 1, towards),    // 21.8 deg off axis: outside 30 deg FOV
                    feature(1.5, 0.3, 1, towards),    // 11.3 deg: inside
                    feature(1.0, 0, 1, -towards),     // seen from behind its surface
                    feature(1.0, 0, 1.5, towards)});  // 26.6 deg above: outside the vertical FOV
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  EXPECT_EQ(sensor.visible(Config(0, 0, 1, 0)), (std::vector<int>{0, 3}));
  EXPECT_TRUE(sensor.visible(Config(0, 0, 1, kPi)).empty());  // facing away
  const FeatureSensor laser(env, FeatureSensorOptions::planar_laser(3.0));
  EXPECT_EQ(laser.visible(Config(0, 0, 1, kPi)), (std::vector<int>{0, 1, 2, 3, 5}));
}

TEST(FeatureSensor, WallsHideFeatures) {
  OccupancyGrid g = make_grid(60, 40, 0.1, 0.05, 0.05);
  fill_rect(g, 2.95, 0.0, 3.05, 2.0, OccupancyGrid::kOccupied);
  GridEnvironment env(g, 0.0, 3.0);
  env.set_features({feature(4.0, 1.0, 1.0, {-1, 0, 0}), feature(4.0, 3.0, 1.0, {-1, 0, 0})});
  FeatureSensorOptions o = FeatureSensorOptions::planar_laser(5.0);
  const FeatureSensor sensor(env, o);
  EXPECT_EQ(sensor.visible(Config(1.0, 1.0, 1.0, 0.0)), (std::vector<int>{1}));
}

TEST(FeatureSensor, JacobianMatchesNumericalDifferentiation) {
  PredicateEnvironment env = open_space();
  Rng rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Feature> features;
  for (int i = 0; i < 20; ++i) features.push_back(feature(u(rng), u(rng), 1.0 + 0.3 * u(rng), {1, 0, 0}));
  env.set_features(features);
  const FeatureSensor sensor(env, FeatureSensorOptions::kinect());
  for (int i = 0; i < 20; ++i) {
    const Config q(0.1 * u(rng), 0.1 * u(rng), 1.0, u(rng));
    const FeatureMeasurement m = sensor.measure(q, i);
    const Eigen::Matrix<double, 3, 4> numeric = test::numerical_jacobian<4>(
        [&](const Eigen::Vector4d& d) -> Eigen::Vector3d { return sensor.predict(q + d, i, m.z[1]); });
    EXPECT_LT((numeric - m.H).norm(), 1e-6) << i;
    EXPECT_NEAR(sensor.predict(q, i, m.z[1])[1], m.z[1], 1e-12);
  }
}

TEST(FeatureSensor, InformationOfAFeatureStraightAheadIsKnown) {
  // From (0, 0, 1, 0) a feature at distance d straight ahead: H rows are
  // range [-1 0 0 0], azimuth [0 -1/d 0 -1], elevation [0 0 -1/d 0].
  PredicateEnvironment env = open_space();
  const double d = 1.5;
  env.set_features({feature(d, 0, 1, {-1, 0, 0})});
  const FeatureSensorOptions o = FeatureSensorOptions::paper_camera();
  const FeatureSensor sensor(env, o);
  const double ir = 1.0 / (o.range_sigma_m * o.range_sigma_m), ib = 1.0 / (o.bearing_sigma_rad * o.bearing_sigma_rad);
  Mat4 expected = Mat4::Zero();
  expected(0, 0) = ir;
  expected(1, 1) = ib / (d * d);
  expected(1, 3) = expected(3, 1) = ib / d;
  expected(3, 3) = ib;
  expected(2, 2) = ib / (d * d);
  EXPECT_LT((sensor.information(Config(0, 0, 1, 0)) - expected).norm(), 1e-12);
  EXPECT_EQ(sensor.information(Config(0, 0, 1, kPi)), Mat4::Zero());
}

TEST(FeatureSensor, UkfInformationTendsToTheEkfsForASmallPrior) {
  PredicateEnvironment env = open_space();
  env.set_features({feature(1.5, 0.2, 1.1, {-1, 0, 0}), feature(1.2, -0.3, 0.8, {-1, 0, 0}),
                    feature(1.8, 0.1, 1.0, {-1, 0, 0})});
  const FeatureSensor sensor(env, FeatureSensorOptions::paper_camera());
  const Config q(0, 0, 1, 0.05);
  const Mat4 ekf = sensor.information(q);
  const Mat4 ukf = sensor.ukf_information(q, 1e-6 * Mat4::Identity());
  EXPECT_LT((ukf - ekf).norm(), 1e-3 * ekf.norm());
  EXPECT_GT(sensor.ukf_information_gain(q, 0.1 * Mat4::Identity()), 0.0);
  EXPECT_EQ(sensor.ukf_information_gain(Config(0, 0, 1, kPi), 0.1 * Mat4::Identity()), 0.0);
}

TEST(FeatureSensor, UkfInformationEqualsTheGenericUkf) {
  // The planner's low-rank eq. 27 against the estimator's generic UKF, which factors the full
  // 3k x 3k innovation covariance: same M for many features, poses and priors.
  PredicateEnvironment env = open_space();
  Rng rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Feature> features;
  for (int i = 0; i < 60; ++i) features.push_back(feature(2.0 + 0.5 * u(rng), 1.5 * u(rng), 1.0 + 0.4 * u(rng), {-1, 0, 0}));
  env.set_features(features);
  for (const FeatureSensorOptions& o : {FeatureSensorOptions::paper_camera(), FeatureSensorOptions::kinect(),
                                        FeatureSensorOptions::planar_laser(4.0)}) {
    const FeatureSensor sensor(env, o);
    for (int trial = 0; trial < 5; ++trial) {
      const Config q(0.2 * u(rng), 0.2 * u(rng), 1.0, 0.3 * u(rng));
      Mat4 A;
      for (int i = 0; i < 16; ++i) A(i) = u(rng);
      const Mat4 prior = 0.05 * A * A.transpose() + 0.01 * Mat4::Identity();
      const std::vector<int> seen = sensor.visible(q);
      ASSERT_GT(seen.size(), 3u);
      Eigen::VectorXd variances(3 * seen.size()), reference(seen.size());
      for (size_t k = 0; k < seen.size(); ++k) {
        const FeatureMeasurement m = sensor.measure(q, seen[k]);
        variances.segment<3>(3 * k) = m.variances;
        reference[k] = m.z[1];
      }
      const auto h = [&](const Config& x) {
        Eigen::VectorXd z(3 * seen.size());
        for (size_t k = 0; k < seen.size(); ++k) z.segment<3>(3 * k) = sensor.predict(x, seen[k], reference[k]);
        return z;
      };
      const Mat4 generic =
          gaussian::ukf_measurement_information(q, prior, h, Eigen::MatrixXd(variances.asDiagonal()));
      const Mat4 fast = sensor.ukf_information(q, prior);
      // Both subtract K S K^T from the prior; with the Kinect the posterior is ~1e-6 of the
      // prior, so both carry ~1e-10 relative rounding: agreement to 1e-7 is all there is.
      EXPECT_LT((fast - generic).norm(), 1e-7 * generic.norm()) << "trial " << trial << " features " << seen.size();
    }
  }
}

TEST(FeatureSensor, InformationTermEqualsTheEstimators) {
  // The diagonal-Q form of H^T Q^-1 H against gaussian::measurement_information (LLT of Q):
  // the same values, not merely close, for Jacobians of every scale and the presets' noise.
  Rng rng(19);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int t = 0; t < 20000; ++t) {
    FeatureMeasurement m;
    for (int i = 0; i < 12; ++i) m.H(i) = u(rng) * std::pow(10.0, 2.0 * u(rng));
    m.H(0, 3) = 0.0;
    m.H(1, 2) = 0.0;
    m.H(1, 3) = -1.0;
    const double r2 = 0.25 + 16.0 * std::abs(u(rng));
    const double sr = t % 3 == 0 ? 1.4e-3 * r2 : t % 3 == 1 ? 1.0 : 0.01, sb = t % 3 == 0 ? 1e-3 : t % 3 == 1 ? 1.0 : 0.0087;
    m.variances = {sr * sr, sb * sb, sb * sb};
    const Mat4 expected = gaussian::measurement_information(m.H, Eigen::Matrix3d(m.variances.asDiagonal()));
    ASSERT_TRUE((FeatureSensor::information_term(m).array() == expected.array()).all()) << "case " << t;
  }
  FeatureMeasurement bad;
  bad.H.setOnes();
  bad.variances = {1.0, 0.0, 1.0};
  EXPECT_THROW(FeatureSensor::information_term(bad), std::invalid_argument);
}

TEST(FeatureSensor, FastVisibilityEqualsTheDefinition) {
  // visible() decides the fields of view by dot products away from their edges and by atan2
  // only within 1e-9 rad of them; visible_reference() asks atan2 always. Features exactly on,
  // 1e-12 rad and 1e-6 rad either side of each edge, straight above and below, and a random
  // cloud, for the three presets and many yaws: the same features, and M bit for bit the sum
  // of measure()'s H^T Q^-1 H over them.
  PredicateEnvironment env = open_space();
  Rng rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<FeatureSensorOptions> presets = {FeatureSensorOptions::paper_camera(), FeatureSensorOptions::kinect(),
                                                     FeatureSensorOptions::planar_laser(4.0)};
  const std::vector<double> yaws = {0.0, 0.3, -1.2, kPi, -kPi, 2.5};
  std::vector<Feature> features;
  for (const FeatureSensorOptions& o : presets)
    for (double yaw : yaws)
      for (double range : {0.7, 1.5, 1.9})
        for (double dh : {-1e-6, -1e-12, 0.0, 1e-12, 1e-6})
          for (double side : {-1.0, 1.0}) {
            // On the horizontal edge (level), and on the vertical edge (straight ahead).
            const double az = yaw + side * (0.5 * o.horizontal_fov_rad + dh);
            features.push_back(feature(range * std::cos(az), range * std::sin(az), 1.0, {-std::cos(az), -std::sin(az), 0}));
            const double el = side * (0.5 * o.vertical_fov_rad + dh);
            features.push_back(feature(range * std::cos(el) * std::cos(yaw), range * std::cos(el) * std::sin(yaw),
                                       1.0 + range * std::sin(el), {-std::cos(yaw), -std::sin(yaw), 0}));
          }
  features.push_back(feature(0.0, 0.0, 2.5, {0, 0, -1}));  // straight above: rho = 0
  features.push_back(feature(0.0, 0.0, 0.2, {0, 0, 1}));   // straight below
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d n(u(rng), u(rng), 0.2 * u(rng));
    features.push_back(feature(4.0 * u(rng), 4.0 * u(rng), 1.0 + 1.5 * u(rng), n));
  }
  env.set_features(features);
  size_t seen_total = 0;
  for (const FeatureSensorOptions& o : presets) {
    const FeatureSensor sensor(env, o);
    std::vector<Config> poses;
    for (double yaw : yaws) poses.emplace_back(0.0, 0.0, 1.0, yaw);
    for (int i = 0; i < 50; ++i) poses.emplace_back(0.3 * u(rng), 0.3 * u(rng), 1.0 + 0.2 * u(rng), kPi * u(rng));
    for (const Config& q : poses) {
      const std::vector<int> seen = sensor.visible(q);
      ASSERT_EQ(seen, sensor.visible_reference(q)) << "yaw " << q[3];
      seen_total += seen.size();
      Mat4 M = Mat4::Zero();
      for (int i : seen) {
        const FeatureMeasurement m = sensor.measure(q, i);
        M += gaussian::measurement_information(m.H, Eigen::Matrix3d(m.variances.asDiagonal()));
      }
      EXPECT_TRUE((sensor.information(q).array() == M.array()).all()) << "yaw " << q[3];
    }
  }
  EXPECT_GT(seen_total, 500u);
  // The edges themselves, from the pose they were placed for: on the edge and 1e-12 inside
  // or outside it atan2 decides (either way, the same as the definition), 1e-6 outside is out.
  const FeatureSensor kinect(env, FeatureSensorOptions::kinect());
  const std::vector<int> ahead = kinect.visible(Config(0.0, 0.0, 1.0, 0.3));
  EXPECT_EQ(ahead, kinect.visible_reference(Config(0.0, 0.0, 1.0, 0.3)));
}

TEST(FeatureSensor, RejectsNonsenseOptions) {
  PredicateEnvironment env = open_space();
  FeatureSensorOptions o;
  o.max_range_m = 0.1;
  EXPECT_THROW(FeatureSensor(env, o), std::invalid_argument);
  o = {};
  o.bearing_sigma_rad = 0.0;
  EXPECT_THROW(FeatureSensor(env, o), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::planner
