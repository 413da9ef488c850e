// Flights and the IMU: the B-spline's algebra, every flight's derivatives against finite
// differences, collision-free flights in every built-in world, the aggressive flight's
// envelope, and noiseless IMU samples that integrate back to the ground truth.

#include <gtest/gtest.h>

#include <cmath>

#include "common/geometry/so3.h"
#include "drivers/sim/bspline.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/imu.h"
#include "sim_fixture.h"

namespace kestrel::sim {
namespace {

TEST(BSplineTest, BasisIsAPartitionOfUnityAndReproducesLines) {
  const auto& m = PeriodicBSpline::basis();
  for (int i = 0; i <= PeriodicBSpline::kDegree; ++i) {
    double row = 0.0;
    for (double x : m[i]) row += x;
    EXPECT_NEAR(row, i == 0 ? 1.0 : 0.0, 1e-12) << "row " << i;
  }
  // Control points on a line: the curve is that line, traversed at constant speed.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 12; ++i) points.emplace_back(i, 2.0 * i, 0.0);
  const PeriodicBSpline line(points, 0.5);
  for (double t = 0.0; t < 3.0; t += 0.173) {
    EXPECT_NEAR(line.position(t).x(), t / 0.5 + 0.5 * (PeriodicBSpline::kDegree - 1), 1e-9);
    EXPECT_NEAR(line.derivative(t, 1).y(), 4.0, 1e-9);
    EXPECT_NEAR(line.derivative(t, 2).norm(), 0.0, 1e-9);
  }
}

TEST(BSplineTest, IsPeriodicAndItsDerivativesAreConsistent) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 9; ++i) points.emplace_back(std::cos(i * 0.7), std::sin(i * 1.3), 0.1 * i * i);
  const PeriodicBSpline s(points, 0.4);
  for (double t = -1.0; t < 5.0; t += 0.31) {
    EXPECT_LT((s.position(t) - s.position(t + s.period_s())).norm(), 1e-9);
    const double h = 1e-5;
    for (int d = 0; d < 3; ++d) {
      const Eigen::Vector3d numeric = (s.derivative(t + h, d) - s.derivative(t - h, d)) / (2 * h);
      EXPECT_LT((numeric - s.derivative(t, d + 1)).norm(), 1e-4 * (1.0 + numeric.norm())) << "order " << d + 1;
    }
  }
}

struct WorldFlight {
  const char* world;
  const char* flight;
};

class FlightTest : public ::testing::TestWithParam<WorldFlight> {};

TEST_P(FlightTest, StartsAtRestIsSmoothConsistentAndCollisionFree) {
  const World& world = test::builtin(GetParam().world);
  const auto flight = make_flight(GetParam().flight, world);
  EXPECT_EQ(flight->name(), GetParam().flight);
  EXPECT_LT(flight->point(0.0).v.norm(), 1e-12);
  EXPECT_LT(first_collision(*flight, world, 0.35, 90.0), 0.0);
  const double h = 1e-4;
  for (double t = 0.37; t < 40.0; t += 1.93) {
    const MotionState s = flight->state(t);
    const Eigen::Vector3d v = (flight->point(t + h).p - flight->point(t - h).p) / (2 * h);
    const Eigen::Vector3d a = (flight->point(t + h).v - flight->point(t - h).v) / (2 * h);
    EXPECT_LT((v - s.v_world).norm(), 1e-5) << "t = " << t;
    EXPECT_LT((a - s.a_world).norm(), 1e-4) << "t = " << t;
    // The angular rate carries the attitude forward: R(t + h) = R(t) Exp(omega h) to O(h^2).
    const Eigen::Matrix3d predicted = s.T_world_body.linear() * so3::exp(s.omega_body * h);
    EXPECT_LT(so3::angle(predicted.transpose() * flight->attitude(t + h)), 1e-6) << "t = " << t;
    // Flatness: thrust along body z, no sideways specific force.
    EXPECT_LT(s.specific_force_body().head<2>().norm(), 1e-9);
  }
}

INSTANTIATE_TEST_SUITE_P(Worlds, FlightTest,
                         ::testing::Values(WorldFlight{"room", "hover"}, WorldFlight{"room", "figure8"},
                                           WorldFlight{"room", "aggressive"}, WorldFlight{"room", "loop"},
                                           WorldFlight{"room", "survey"}, WorldFlight{"floor", "loop"},
                                           WorldFlight{"floor", "figure8"}, WorldFlight{"office", "loop"},
                                           WorldFlight{"office", "aggressive"}),
                         [](const ::testing::TestParamInfo<WorldFlight>& p) {
                           return std::string(p.param.world) + "_" + p.param.flight;
                         });

TEST(FlightTest, AggressiveFlightReachesItsEnvelope) {
  const auto flight = make_flight("aggressive", test::builtin("room"));
  double speed = 0.0, yaw_rate = 0.0;
  for (double t = 0.0; t < 30.0; t += 0.01) {
    const MotionState s = flight->state(t);
    speed = std::max(speed, s.v_world.norm());
    yaw_rate = std::max(yaw_rate, std::abs((s.T_world_body.linear() * s.omega_body).z()));
  }
  EXPECT_GT(speed, 1.2);
  EXPECT_LT(speed, 1.7);
  EXPECT_GT(yaw_rate * 180.0 / 3.14159265358979, 90.0);
  EXPECT_LT(yaw_rate * 180.0 / 3.14159265358979, 140.0);
}

TEST(FlightTest, LoopInCorridorsRevisitsItsStart) {
  const World& world = test::builtin("floor");
  const auto flight = make_flight("loop", world);
  const auto& spline = dynamic_cast<const SplineFlight&>(*flight);
  const double period = spline.period_s();
  EXPECT_GT(period, 30.0);  // a real tour, not a hop
  const double t0 = flight->ramp_s() + 1.0;
  EXPECT_LT((flight->point(t0).p - flight->point(t0 + period).p).norm(), 1e-9);
  double farthest = 0.0;
  for (double t = t0; t < t0 + period; t += 0.5)
    farthest = std::max(farthest, (flight->point(t).p - flight->point(t0).p).norm());
  EXPECT_GT(farthest, 8.0);
}

class ImuIntegrationTest : public ::testing::TestWithParam<const char*> {};

TEST_P(ImuIntegrationTest, NoiselessSamplesIntegrateBackToTheTruthOverTenSeconds) {
  const auto flight = make_flight(GetParam(), test::builtin("room"));
  ImuOptions options;
  options.noise = false;
  ImuSimulator imu(*flight, options, 1);
  const test::Integrated x = test::integrate(*flight, imu, 10.0);
  const MotionState truth = flight->state(10.0);
  EXPECT_LT((x.p - truth.T_world_body.translation()).norm(), 1e-3);
  EXPECT_LT((x.v - truth.v_world).norm(), 1e-3);
  EXPECT_LT(so3::angle(x.q.toRotationMatrix().transpose() * truth.T_world_body.linear()), 1e-5);
}

INSTANTIATE_TEST_SUITE_P(Flights, ImuIntegrationTest, ::testing::Values("figure8", "aggressive", "loop", "survey"));

TEST(ImuTest, NoiseAndBiasesHaveTheConfiguredStatistics) {
  const auto flight = make_flight("hover", test::builtin("room"));
  ImuOptions options;
  ImuSimulator noisy(*flight, options, 5);
  options.noise = false;
  ImuSimulator exact(*flight, options, 5);
  const int n = 20000;
  double sum_sq = 0.0;
  ImuSample first, last;
  for (int k = 0; k < n; ++k) {
    const ImuSample a = noisy.next(), b = exact.next();
    if (k == 0) first = a;
    last = a;
    const Eigen::Vector3d white = a.gyro - b.gyro - a.gyro_bias;
    sum_sq += white.squaredNorm();
  }
  const double sigma = std::sqrt(sum_sq / (3.0 * n));
  const double expected = ImuOptions{}.gyro_noise_density * std::sqrt(ImuOptions{}.rate_hz);
  EXPECT_NEAR(sigma, expected, 0.05 * expected);
  EXPECT_GT((first.gyro_bias - last.gyro_bias).norm(), 0.0);  // the bias walks
  EXPECT_GT(first.accel_bias.norm(), 0.0);
  noisy.reset();
  EXPECT_EQ(noisy.next().gyro, first.gyro);  // reset replays the same draws
}

}  // namespace
}  // namespace kestrel::sim
