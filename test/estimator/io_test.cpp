// The estimator's message side: conversions (and the bad messages they refuse), and the
// offline run over an LCM log, which must equal the library fed the same inputs and count
// what it skips. The logs are synthesised here (a still vehicle, biased IMU, synthetic VO).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "estimator/eval/synthetic_vo.h"
#include "estimator/log_run.h"
#include "estimator/messages.h"
#include "kestrel/ground_truth_t.hpp"
#include "test/estimator/analytic_motion.h"
#include "test/estimator/synthetic_log.h"
#include "test/support/test_support.h"

namespace kestrel::estimator {
namespace {

using test::imu_message;
using test::SyntheticLog;
using test::vo_message;
using test::write_log;


TEST(Messages, ImuReadingKeepsThePartsItHasAndRefusesNanOrNothingNamingTheChannel) {
  ImuSample s;
  s.utime = 5;
  s.gyro << 0.1, 0.2, 0.3;
  s.accel << 0.0, 0.5, 9.8;
  kestrel::imu_t m = imu_message(s);
  const ImuReading both = imu_from_message(m, "IMU");
  ASSERT_TRUE(both.complete());
  EXPECT_EQ(both.sample().gyro, s.gyro);
  EXPECT_EQ(both.sample().accel, s.accel);
  m.fields = kestrel::imu_t::HAS_ACCEL;  // the Kinect's (and TUM's) accelerometer-only IMU
  const ImuReading accel_only = imu_from_message(m, "IMU");
  EXPECT_FALSE(accel_only.gyro.has_value());
  ASSERT_TRUE(accel_only.accel.has_value());
  EXPECT_EQ(*accel_only.accel, s.accel);
  m.fields = 0;
  try {
    imu_from_message(m, "IMU");
    FAIL() << "a reading with nothing in it accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("IMU"), std::string::npos);
  }
  m = imu_message(s);
  m.linear_acceleration[2] = static_cast<double>(INFINITY);
  EXPECT_THROW(imu_from_message(m, "IMU"), InputError);
  m = imu_message(s);
  m.fields = kestrel::imu_t::HAS_ACCEL;
  m.angular_velocity[0] = std::nan("");  // not there: not looked at
  EXPECT_NO_THROW(imu_from_message(m, "IMU"));
}

TEST(Messages, VoFailureCarriesNoPoseAndACorruptPoseIsRefused) {
  VoUpdate u;
  u.utime = 2000;
  u.reference_utime = 1000;
  u.ok = true;
  u.T_refcam_curcam.translation() << 0.1, 0.2, 0.3;
  u.covariance = Matrix6d::Identity() * 1e-4;
  kestrel::vo_update_t m = vo_message(u);
  const VoUpdate back = vo_from_message(m, "VO_UPDATE");
  EXPECT_TRUE(back.ok);
  EXPECT_TRUE(back.T_refcam_curcam.isApprox(u.T_refcam_curcam));
  EXPECT_TRUE(back.covariance.isApprox(u.covariance));
  m.status = kestrel::vo_update_t::STATUS_INSUFFICIENT_INLIERS;
  m.T_reference_current.orientation[0] = std::nan("");  // ignored for a failure
  EXPECT_FALSE(vo_from_message(m, "VO_UPDATE").ok);
  m.status = kestrel::vo_update_t::STATUS_OK;
  EXPECT_THROW(vo_from_message(m, "VO_UPDATE"), InputError);
}

TEST(Messages, StateCarriesTheOutputAndItsCovarianceRowMajor) {
  EstimatorOutput out;
  out.utime = 77;
  out.status = Status::kDegraded;
  out.nav.p_world_body << 1, 2, 3;
  out.nav.v_world_body << 4, 5, 6;
  for (int r = 0; r < 15; ++r)
    for (int c = 0; c < 15; ++c) out.covariance(r, c) = r * 100 + c;
  kestrel::state_t m = state_to_message(out, EstimatorMode::kImu, FilterKind::kUkf, 9);
  EXPECT_EQ(m.utime, 77);
  EXPECT_EQ(m.seq, 9);
  EXPECT_EQ(m.filter, kestrel::state_t::FILTER_UKF);
  EXPECT_EQ(m.status, kestrel::state_t::STATUS_DEGRADED);
  EXPECT_EQ(m.T_world_body.position[2], 3.0);
  EXPECT_EQ(m.velocity[1], 5.0);
  ASSERT_EQ(m.cov_dim, 15);
  EXPECT_EQ(m.covariance[2][7], 207.0);
  m = state_to_message(out, EstimatorMode::kVisualOnly, FilterKind::kUkf, 10);
  EXPECT_EQ(m.filter, kestrel::state_t::FILTER_VISUAL_ONLY);
}

TEST(LogRun, EqualsTheLibraryFedTheSameInputsAndCountsWhatItSkips) {
  kestrel::test::TempDir dir;
  const std::string path = (dir / "flight.lcmlog").string();
  const SyntheticLog log = write_log(path, 6.0, true);
  EstimatorOptions options;
  options.init.yaw = 0.3;
  const LogRunResult r = run_log(path, options);
  EXPECT_EQ(r.skips.rejected, 2);  // the NaN sample and the corrupt VO
  EXPECT_NE(r.skips.first_reason.find("IMU"), std::string::npos) << r.skips.first_reason;
  EXPECT_EQ(r.counters.imu_duplicate, 1);
  EXPECT_EQ(r.correction_messages, 1);
  EXPECT_EQ(r.counters.corrections_received, 1);
  EXPECT_GT(r.counters.vo_applied, 100);

  // The same inputs, in the same order, straight into the library.
  Estimator e(options);
  size_t vo_i = 0;
  std::vector<StampedPose> expected;
  for (const ImuSample& s : log.imu) {
    while (vo_i < log.vo.size() && log.vo[vo_i].utime + 30000 <= s.utime) e.add_vo(log.vo[vo_i++]);
    if (e.add_imu(s) == Verdict::kAccepted && e.output()) expected.push_back({s.utime, e.output()->nav.T_world_body()});
    if (s.utime == log.imu[800].utime) {
      PoseCorrection c;
      c.utime = log.imu[600].utime;
      c.revision = 1;
      c.T_world_body = test::AnalyticMotion::still(0.3).state(0.0).T_world_body();
      e.add_correction(c);
      expected.back().T = e.output()->nav.T_world_body();
    }
  }
  ASSERT_EQ(r.trajectory.size(), expected.size());
  // The trajectory records the state when each IMU sample arrived; a correction in between
  // moves later states only, so compare from after it.
  const auto& got = r.trajectory.poses();
  EXPECT_EQ(got.back().utime, expected.back().utime);
  EXPECT_TRUE(got.back().T.isApprox(expected.back().T, 1e-12));
  // A still vehicle, origin and yaw given. On the IMU alone the horizontal accelerometer
  // bias (0.036 m/s^2, read as tilt by the static initialisation) would drift it 0.65 m in
  // 6 s; with the VO it wanders by the noise of the anchoring update (sigma 4-6 mm per axis)
  // and the start-up velocity uncertainty: about 1.5 cm at worst here.
  double worst = 0.0;
  for (const StampedPose& p : got) worst = std::max(worst, p.T.translation().norm());
  EXPECT_LT(worst, 0.03);
}

TEST(LogRun, ALogWithoutImuIsAnInputErrorForTheImuFilterAndOneWithoutInputsForAny) {
  kestrel::test::TempDir dir;
  const std::string path = (dir / "no_imu.lcmlog").string();
  {
    transport::LogWriter log(path);
    log.write_message("VO_UPDATE", 1, vo_message(VoUpdate{}));
    log.close();
  }
  EstimatorOptions imu_only;
  imu_only.mode = EstimatorMode::kImu;
  EXPECT_THROW(run_log(path, imu_only), InputError);
  EXPECT_NO_THROW(run_log(path, EstimatorOptions{}));  // auto: the visual odometry alone
  const std::string empty = (dir / "empty.lcmlog").string();
  {
    transport::LogWriter log(empty);
    log.write_message("GROUND_TRUTH", 1, kestrel::ground_truth_t{});
    log.close();
  }
  EXPECT_THROW(run_log(empty, EstimatorOptions{}), InputError);
  EXPECT_THROW(run_log((dir / "missing.lcmlog").string(), EstimatorOptions{}), InputError);
}

TEST(LogRun, VoAndCameraFrameTruthAreReadForTheFit) {
  kestrel::test::TempDir dir;
  const std::string path = (dir / "fit.lcmlog").string();
  const Eigen::Isometry3d T_body_camera = se3::exp((Vector6d() << 0.1, 0, 0, -1.2, 0, -1.2).finished());
  {
    transport::LogWriter log(path);
    VoUpdate u;
    u.utime = 2000;
    u.reference_utime = 1000;
    u.ok = true;
    u.T_body_camera = T_body_camera;
    u.covariance = Matrix6d::Identity() * 1e-4;
    for (int64_t t : {1000, 2000}) {
      kestrel::ground_truth_t g{};
      g.utime = t;
      g.frame = kestrel::ground_truth_t::FRAME_CAMERA;
      g.T_world_frame = transport::to_message(T_body_camera);  // body at the origin
      log.write_message("GROUND_TRUTH", t, g);
    }
    log.write_message("VO_UPDATE", 2000, vo_message(u));
    log.close();
  }
  const VoAndTruth r = read_vo_and_truth(path);
  ASSERT_EQ(r.updates.size(), 1u);
  ASSERT_EQ(r.truth.size(), 2u);
  EXPECT_TRUE(r.truth.poses()[0].T.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
}

}  // namespace
}  // namespace kestrel::estimator
