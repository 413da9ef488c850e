// VO + SLAM on the real TUM sequences (label data; skips without ../shared/data), the VO and
// the keyframe features' timing with the recordings' camera profile (kinect1), both through
// freiburg1's lens distortion: on each, the ATE of the optimised trajectory is no worse than
// the odometry's (issue 6), and on fr1_rpy, where the camera sweeps back over the desk, loops
// are closed and the ATE drops; with the built-in (trained) vocabulary and the online one
// alike, and no loop closure is false.

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "common/numbers.h"
#include "slam/place/builtin_vocabulary.h"
#include "slam/sequence_run.h"
#include "test/support/test_support.h"
#include "metrics/evaluate.h"
#include "vo/sequence_run.h"

namespace kestrel::slam {
namespace {

// kestrel eval's ATE (RMSE after the rigid alignment, at the estimate's frames, the ground
// truth interpolated within 20 ms): the one ATE of the project.
double ate_rmse(const Trajectory& estimate, const Trajectory& truth) {
  return metrics::evaluate(metrics::frame_times(estimate), estimate, truth, metrics::EvalOptions{}).ate.error_m.rmse;
}

class SlamOnTum : public ::testing::TestWithParam<std::tuple<const char*, bool>> {};

TEST_P(SlamOnTum, AteIsNoWorseThanTheOdometrys) {
  const std::string name = std::get<0>(GetParam());
  const bool builtin = std::get<1>(GetParam());
  KESTREL_REQUIRE_TUM(folder, name);
  const vo::LoadedSequence sequence = vo::load_tum_sequence(folder.string());
  ASSERT_FALSE(sequence.ground_truth.empty());
  const SlamRun run =
      run_slam_sequence(sequence.frames, vo::tum_sensor(folder.string()), vo::VoOptions{}, SlamOptions{},
                        builtin ? builtin_vocabulary() : nullptr);
  ASSERT_GT(run.slam.size(), sequence.frames.size() * 9 / 10);
  const double vo_ate = ate_rmse(run.vo, sequence.ground_truth);
  const double slam_ate = ate_rmse(run.slam, sequence.ground_truth);
  std::cout << name << (builtin ? " (built-in vocabulary)" : " (online vocabulary)") << ": ATE VO " << vo_ate << " m, SLAM " << slam_ate << " m, " << run.keyframes
            << " keyframes, " << run.loop_closures << " loop closures\n";
  // Issue 6: SLAM no worse than the odometry, on every sequence and vocabulary. fr1_xyz's one
  // loop (built-in vocabulary) once left SLAM above the VO (0.977 vs 0.893 cm; held to 1.1 x
  // 0.977 cm); since the VO uses freiburg1's lens distortion with the kinect1 profile's dense
  // weight (1.133 cm there) SLAM is below it: 1.063 cm with raw keypoint pixels, 1.026 cm with
  // the keyframe features through the lens too, 0.968 cm with frames between keyframes placed
  // by the interpolated correction; since the Kinect's loops take a 1 degree rotation floor and
  // its VO keeps a near keyframe, 0.927 against the VO's 0.944 cm (slam/README.md).
  EXPECT_LE(slam_ate, vo_ate + 1e-9);
  for (const LoopError& e : loop_errors(run, sequence.ground_truth)) {
    ASSERT_TRUE(e.has_truth);
    std::cout << "  loop " << e.edge.from_utime << " -> " << e.edge.to_utime << ": " << e.translation_m * 100.0
              << " cm, " << e.rotation_rad * 180.0 / kPi << " deg\n";
    EXPECT_LT(e.translation_m, 0.10) << "a false loop closure";
    EXPECT_LT(e.rotation_rad, 3.0 * kPi / 180.0) << "a false loop closure";
  }
  if (name == "rgbd_dataset_freiburg1_rpy") {
    EXPECT_GE(run.loop_closures, 1);
    EXPECT_LT(slam_ate, 0.8 * vo_ate);
  }
}

INSTANTIATE_TEST_SUITE_P(Sequences, SlamOnTum,
                         ::testing::Combine(::testing::Values("rgbd_dataset_freiburg1_xyz",
                                                              "rgbd_dataset_freiburg1_rpy"),
                                            ::testing::Bool()),
                         [](const ::testing::TestParamInfo<SlamOnTum::ParamType>& p) {
                           const std::string name = std::get<0>(p.param);
                           return name.substr(name.rfind('_') + 1) + (std::get<1>(p.param) ? "_builtin" : "_online");
                         });

}  // namespace
}  // namespace kestrel::slam
