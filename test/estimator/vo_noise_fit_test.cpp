// The constant VO noise model fitted against ground truth recovers the noise the synthetic
// VO was given, sees a bias, and refuses input with nothing to fit.

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "estimator/eval/synthetic_vo.h"
#include "estimator/vo_noise_fit.h"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator {
namespace {

struct VoRun {
  std::vector<VoUpdate> updates;
  Trajectory truth;
};

VoRun synthetic_run(const SyntheticVoOptions& vo_options, double duration_s) {
  const auto motion = test::AnalyticMotion::aggressive();
  VoRun r;
  for (int64_t utime = 1000000; utime <= 1000000 + static_cast<int64_t>(duration_s * 1e6);
       utime += 10000) {  // truth at 100 Hz
    const Eigen::Isometry3d T = motion.state(test::seconds(utime)).T_world_body();
    r.truth.push_back(utime, T);
  }
  // Frames at 30 Hz, most of them between truth samples (the fit interpolates the truth).
  SyntheticVo vo(vo_options, 42);
  for (int64_t utime = 1000000; utime < 1000000 + static_cast<int64_t>(duration_s * 1e6);
       utime += 33333)
    r.updates.push_back(vo.next(utime, motion.state(test::seconds(utime)).T_world_body()));
  return r;
}

TEST(VoNoiseFit, RecoversTheSyntheticVoSigmas) {
  SyntheticVoOptions o;
  o.keyframe_share = 0.0;  // independent errors: the standard error below holds
  o.T_body_camera.translation() << 0.1, 0.0, -0.05;
  o.T_body_camera.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // optical frame on a body x-forward
  const VoRun r = synthetic_run(o, 60.0);
  const VoNoiseFit fit = fit_vo_noise(r.updates, r.truth, 20000);
  EXPECT_EQ(fit.failed, 1);  // the first frame has no reference
  EXPECT_EQ(fit.uncovered, 0);
  ASSERT_GT(fit.used, 1500);
  for (int i = 0; i < 6; ++i) {
    // RMS of ~2000 Gaussian samples: standard error 1.6 %; the truth is interpolated at
    // 100 Hz on a smooth motion, which adds far less than that.
    EXPECT_NEAR(fit.sigma[i], o.sigma[i], 0.07 * o.sigma[i]) << "axis " << i;
    EXPECT_LT(std::abs(fit.mean[i]), 0.1 * o.sigma[i]) << "axis " << i;
  }
  EXPECT_GT(fit.mean_interval_s, 0.03);
}

TEST(VoNoiseFit, MeasuresTheShareOfTheErrorCommonToAKeyframe) {
  // Keyframes held for tens of frames, so that each gives many pairs of updates.
  SyntheticVoOptions o;
  o.keyframe_distance_m = 1.0;
  o.keyframe_angle_rad = 0.6;
  for (const double share : {0.0, 0.3, 0.6}) {
    o.keyframe_share = share;
    const VoRun r = synthetic_run(o, 120.0);
    const VoNoiseFit fit = fit_vo_noise(r.updates, r.truth, 20000);
    ASSERT_GT(fit.keyframes_with_pairs, 50) << "share " << share;
    // ~100 keyframes of ~30 updates: the estimate's spread is a few hundredths.
    EXPECT_NEAR(fit.keyframe_share, share, 0.08) << "share " << share;
    // The synthetic keyframe error does not fade: the same share at every lag.
    EXPECT_NEAR(fit.share_by_lag[0].share, share, 0.1) << "share " << share;
    EXPECT_NEAR(fit.share_by_lag[4].share, share, 0.1) << "share " << share;
    EXPECT_GT(fit.share_by_lag[4].pairs, 1000);
    // The reported covariance is the whole noise.
    EXPECT_NEAR(fit.reported_nees, 1.0, 0.1) << "share " << share;
    // Updates either side of a re-key share nothing here (the synthetic VO's error is drawn
    // per update and per keyframe, not per frame).
    EXPECT_GT(fit.rekey_pairs, 50);
    EXPECT_NEAR(fit.share_across_rekey, 0.0, 0.15) << "share " << share;
    // The whole error is still what each update reports.
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(fit.sigma[i], o.sigma[i], 0.15 * o.sigma[i]);
  }
}

TEST(VoNoiseFit, ErrorFollowsTheFilterResidualConvention) {
  // A known perturbation true = measured ⊞ e comes back as e.
  VoUpdate u;
  u.ok = true;
  u.T_body_camera.translation() << 0.2, 0.1, 0.0;
  const Eigen::Isometry3d T_world_ref = se3::exp((Vector6d() << 1, 2, 3, 0.1, -0.2, 0.3).finished());
  const Eigen::Isometry3d T_world_cur = se3::exp((Vector6d() << 1.3, 2.1, 2.8, 0.2, -0.1, 0.5).finished());
  const Eigen::Isometry3d T_true = (T_world_ref * u.T_body_camera).inverse() * (T_world_cur * u.T_body_camera);
  const Vector6d e = (Vector6d() << 0.01, -0.02, 0.005, 0.003, -0.004, 0.002).finished();
  u.T_refcam_curcam.translation() = T_true.translation() - e.head<3>();
  u.T_refcam_curcam.linear() = T_true.linear() * so3::exp(e.tail<3>()).transpose();
  EXPECT_TRUE(vo_error(u, T_world_ref, T_world_cur).isApprox(e, 1e-9));
}

TEST(VoNoiseFit, NothingToFitIsAnInputError) {
  const VoRun r = synthetic_run(SyntheticVoOptions{}, 2.0);
  Trajectory elsewhere;  // truth that does not cover the updates
  elsewhere.push_back(1, Eigen::Isometry3d::Identity());
  elsewhere.push_back(2, Eigen::Isometry3d::Identity());
  EXPECT_THROW(fit_vo_noise(r.updates, elsewhere), InputError);
  EXPECT_THROW(fit_vo_noise({}, r.truth), InputError);
}

}  // namespace
}  // namespace kestrel::estimator
