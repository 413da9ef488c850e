// Bad frames give a status and a message, change no state, and the next good frame recovers:
// all black, no depth, wrong size, non-finite camera, duplicate and backwards time stamps,
// options that cannot run.

#include <gtest/gtest.h>

#include <limits>

#include "test/vo/synthetic_scene.h"
#include "vo/odometry.h"
#include "vo/option_keys.h"

namespace kestrel::vo {
namespace {

RgbdFrame good(int k) {
  static const test::SyntheticScene scene(21);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.01 * k, 0.0, 0.0);
  return scene.render(T, test::test_camera(), 1000000 + 33333 * k);
}

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(vo.process(good(0)).status, VoStatus::kNoReference);
    ASSERT_EQ(vo.process(good(1)).status, VoStatus::kOk);
  }
  void expect_recovers(int k) {
    const VoResult r = vo.process(good(k));
    EXPECT_EQ(r.status, VoStatus::kOk) << r.message;
  }
  VisualOdometry vo;
};

TEST_F(BadInput, AllBlackFrame) {
  RgbdFrame f = good(2);
  f.rgb.setTo(cv::Scalar::all(0));
  const VoResult r = vo.process(f);
  EXPECT_EQ(r.status, VoStatus::kInsufficientFeatures);
  EXPECT_NE(r.message.find("too few features"), std::string::npos) << r.message;
  expect_recovers(3);
}

TEST_F(BadInput, NoDepth) {
  RgbdFrame f = good(2);
  f.depth_mm.setTo(cv::Scalar::all(0));
  const VoResult r = vo.process(f);
  EXPECT_EQ(r.status, VoStatus::kInsufficientDepth);
  EXPECT_NE(r.message.find("valid depth"), std::string::npos) << r.message;
  expect_recovers(3);
}

TEST_F(BadInput, WrongSize) {
  RgbdFrame f = good(2);
  f.depth_mm = cv::Mat(240, 320, CV_16UC1, cv::Scalar(1000));
  const VoResult r = vo.process(f);
  EXPECT_EQ(r.status, VoStatus::kBadInput);
  EXPECT_FALSE(r.message.empty());
  expect_recovers(3);
}

TEST_F(BadInput, NonFiniteCamera) {
  RgbdFrame f = good(2);
  f.camera.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(vo.process(f).status, VoStatus::kBadInput);
  f = good(2);
  f.T_body_camera.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(vo.process(f).status, VoStatus::kBadInput);
  expect_recovers(3);
}

TEST_F(BadInput, DuplicateAndBackwardsTimeStamps) {
  const VoResult dup = vo.process(good(1));
  EXPECT_EQ(dup.status, VoStatus::kBadInput);
  EXPECT_NE(dup.message.find("not after"), std::string::npos) << dup.message;
  EXPECT_EQ(vo.process(good(0)).status, VoStatus::kBadInput);
  expect_recovers(2);
}

TEST_F(BadInput, TwoFailuresInARowRestartFromTheCurrentFrame) {
  // Another room: nothing matches the reference, twice; the second failure restarts the
  // odometry from that frame, and the next view of the new room is measured against it.
  const test::SyntheticScene other(99);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const VoResult first = vo.process(other.render(T, test::test_camera(), 2000000));
  EXPECT_NE(first.status, VoStatus::kOk);
  EXPECT_FALSE(first.new_reference);
  T.translation().x() = 0.01;
  const VoResult second = vo.process(other.render(T, test::test_camera(), 2033333));
  EXPECT_NE(second.status, VoStatus::kOk);
  EXPECT_TRUE(second.new_reference) << second.message;
  EXPECT_NE(second.message.find("restarted"), std::string::npos) << second.message;
  T.translation().x() = 0.02;
  const VoResult third = vo.process(other.render(T, test::test_camera(), 2066666));
  ASSERT_EQ(third.status, VoStatus::kOk) << third.message;
  EXPECT_EQ(third.reference_utime, 2033333);
  EXPECT_NEAR(third.T_reference_current.translation().x(), 0.01, 0.002);
}

TEST_F(BadInput, AfterABlankViewTheFirstUnmatchableFrameRestarts) {
  // A blank wall (no features) for a few frames, then a place the old reference does not
  // show: the first frame with features becomes the new reference at once (it does not wait
  // for a second failure), and the next frame has a motion again.
  for (int k = 2; k < 6; ++k) {
    RgbdFrame f = good(k);
    f.rgb.setTo(cv::Scalar::all(128));
    ASSERT_EQ(vo.process(f).status, VoStatus::kInsufficientFeatures);
  }
  const test::SyntheticScene other(99);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const VoResult first = vo.process(other.render(T, test::test_camera(), 2000000));
  EXPECT_NE(first.status, VoStatus::kOk);
  EXPECT_TRUE(first.new_reference) << first.message;
  T.translation().x() = 0.01;
  const VoResult second = vo.process(other.render(T, test::test_camera(), 2033333));
  ASSERT_EQ(second.status, VoStatus::kOk) << second.message;
  EXPECT_EQ(second.reference_utime, 2000000);
  EXPECT_NEAR(second.T_reference_current.translation().x(), 0.01, 0.002);
}

TEST(Options, UnusableValuesAreRejectedByName) {
  VoOptions o;
  o.match.window_size = 8;
  try {
    VisualOdometry vo(o);
    FAIL() << "an even window was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("match.window_size"), std::string::npos) << e.what();
  }
  o = VoOptions{};
  o.pyramid.levels = 5;
  EXPECT_THROW(VisualOdometry{o}, std::invalid_argument);
}

TEST(Options, SetByNameAndRejectedByName) {
  VoOptions o;
  set_option(o, "fast.threshold", "15");
  set_option(o, "inliers.method", "ransac");
  set_option(o, "refinement.bidirectional", "false");
  EXPECT_EQ(o.fast.threshold, 15);
  EXPECT_EQ(o.inliers.method, InlierMethod::kRansac);
  EXPECT_FALSE(o.refinement.bidirectional);
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"fast.thresh", "15"}, {"fast.threshold", "fifteen"}, {"match.window_size", "8"},
           {"refinement.solver", "lm"}, {"bucket.enabled", "yes"}}) {
    try {
      set_option(o, key, value);
      ADD_FAILURE() << key << "=" << value << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key.substr(0, 10)), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(o.fast.threshold, 15) << "a rejected value changes nothing";
  set_option(o, "keyframe.min_inlier_fraction_to_keep", "0.8");
  EXPECT_EQ(o.keyframe.min_inlier_fraction_to_keep, 0.8);
  EXPECT_THROW(set_option(o, "keyframe.min_inlier_fraction_to_keep", "1.5"), std::invalid_argument);
  set_option(o, "dense.weight", "0.1");
  EXPECT_EQ(o.dense.weight, 0.1);
  EXPECT_THROW(set_option(o, "dense.stride", "0"), std::invalid_argument);
  set_option(o, "refinement.pixel_sigma_from_residuals", "false");
  EXPECT_FALSE(o.refinement.pixel_sigma_from_residuals);
  EXPECT_THROW(set_option(o, "refinement.min_pixel_sigma", "0"), std::invalid_argument);
  set_option(o, "keyframe.min_inliers_to_keep_near", "0");
  EXPECT_EQ(o.keyframe.min_inliers_to_keep_near, 0);
  EXPECT_THROW(set_option(o, "keyframe.near_translation_m", "-0.01"), std::invalid_argument);
  set_option(o, "keyframe.floor_cap_fraction", "0.7");
  EXPECT_EQ(o.keyframe.floor_cap_fraction, 0.7);
  EXPECT_THROW(set_option(o, "keyframe.floor_cap_fraction", "-0.1"), std::invalid_argument);
  EXPECT_THROW(set_option(o, "keyframe.floor_cap_fraction", "1.5"), std::invalid_argument);
  EXPECT_EQ(o.keyframe.floor_cap_fraction, 0.7) << "a rejected value changes nothing";
  EXPECT_EQ(describe_options(o).size(), 73u);
}

}  // namespace
}  // namespace kestrel::vo
