// The whole odometry on the synthetic scene rendered along a known trajectory: every frame
// after the first gets a motion, chained poses follow the truth, keyframes are kept while
// the view overlaps, and every variant of the paper's Table 1 runs.

#include <gtest/gtest.h>

#include <set>

#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "test/vo/synthetic_scene.h"
#include "vo/odometry.h"
#include "vo/pose_chain.h"
#include "vo/variants.h"

namespace kestrel::vo {
namespace {

// 1 cm and 0.4 degrees per frame (30 Hz: 0.3 m/s, 12 deg/s), a gentle arc in the room.
Eigen::Isometry3d truth(int k) {
  return se3::exp((Vector6d() << 0.010 * k, -0.004 * k, 0.006 * k, 0.003 * k, 0.007 * k, -0.002 * k).finished());
}

struct Rendered {
  std::vector<RgbdFrame> frames;
};

const Rendered& rendered() {
  static const Rendered r = [] {
    Rendered out;
    const test::SyntheticScene scene(11);
    for (int k = 0; k < 8; ++k) out.frames.push_back(scene.render(truth(k), test::test_camera(), 1000000 + 33333 * k));
    return out;
  }();
  return r;
}

void run_and_check(const VoOptions& options, double max_translation_m, double max_rotation_deg,
                   const std::string& what) {
  VisualOdometry vo(options);
  PoseChain chain;
  const auto& frames = rendered().frames;
  for (size_t k = 0; k < frames.size(); ++k) {
    const VoResult r = vo.process(frames[k]);
    const auto pose = chain.add(r);
    if (k == 0) {
      EXPECT_EQ(r.status, VoStatus::kNoReference) << what;
      EXPECT_TRUE(r.new_reference);
      continue;
    }
    ASSERT_EQ(r.status, VoStatus::kOk) << what << " frame " << k << ": " << r.message;
    ASSERT_TRUE(pose.has_value());
    EXPECT_GT(r.num_reprojection_inliers, 50) << what;
    EXPECT_TRUE(r.covariance.allFinite());
    EXPECT_GT(r.covariance.diagonal().minCoeff(), 0.0);
    const Eigen::Isometry3d T_true = truth(0).inverse() * truth(int(k));
    EXPECT_LT(se3::translation_distance(*pose, T_true), max_translation_m) << what << " frame " << k;
    EXPECT_LT(se3::rotation_distance(*pose, T_true) * 180.0 / kPi, max_rotation_deg) << what << " frame " << k;
  }
}

TEST(Pipeline, FollowsTheSyntheticTrajectory) {
  run_and_check(VoOptions{}, 0.003, 0.1, "default");
}

TEST(Pipeline, KeepsTheKeyframeWhileItOverlaps) {
  VisualOdometry vo;
  const auto& frames = rendered().frames;
  vo.process(frames[0]);
  const VoResult r1 = vo.process(frames[1]);
  ASSERT_EQ(r1.status, VoStatus::kOk);
  EXPECT_EQ(r1.reference_utime, frames[0].utime);
  EXPECT_FALSE(r1.new_reference);
  const VoResult r2 = vo.process(frames[2]);
  ASSERT_EQ(r2.status, VoStatus::kOk);
  EXPECT_EQ(r2.reference_utime, frames[0].utime) << "frame 2 is matched against the keyframe";
}

// Runs `options` over the arc and checks that a frame becomes the reference exactly when its
// inliers fall below `fraction` of the keyframe's inliers at its first match; that happens at
// least once, and some frame past a keyframe's first match keeps it.
void expect_rekeys_below_fraction_of_first_match(const VoOptions& options, double fraction) {
  const auto& frames = rendered().frames;
  VisualOdometry vo(options);
  vo.process(frames[0]);
  int first = 0;  // the current keyframe's inliers at its first match
  int kept_past_first = 0, new_references = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const VoResult r = vo.process(frames[k]);
    ASSERT_EQ(r.status, VoStatus::kOk) << r.message;
    const bool first_match = first == 0;
    if (first_match) first = r.num_reprojection_inliers;
    EXPECT_EQ(r.new_reference, r.num_reprojection_inliers < fraction * first)
        << "frame " << k << ": " << r.num_reprojection_inliers << " vs " << first;
    if (r.new_reference) {
      first = 0;
      ++new_references;
    } else if (!first_match) {
      ++kept_past_first;
    }
  }
  EXPECT_GT(new_references, 0) << "the arc loses more than " << 100 * (1 - fraction) << " % of a first view's inliers";
  EXPECT_GT(kept_past_first, 0) << "a keyframe is kept past its first match while it holds the share";
}

// The relative keyframe rule: a frame becomes the reference exactly when its inliers fall
// below the fraction of the keyframe's inliers at its first match (floor off); with both
// rules off the first frame stays the reference over the whole arc.
TEST(Pipeline, RelativeKeyframeRuleFollowsTheFirstMatchCount) {
  const auto& frames = rendered().frames;
  VoOptions off;
  off.keyframe.min_inliers_to_keep = 0;
  off.keyframe.min_inlier_fraction_to_keep = 0.0;
  VisualOdometry never(off);
  never.process(frames[0]);
  for (size_t k = 1; k < frames.size(); ++k) {
    const VoResult r = never.process(frames[k]);
    ASSERT_EQ(r.status, VoStatus::kOk) << r.message;
    EXPECT_EQ(r.reference_utime, frames[0].utime) << "frame " << k;
    EXPECT_FALSE(r.new_reference) << "frame " << k;
  }

  VoOptions relative = off;
  relative.keyframe.min_inlier_fraction_to_keep = 0.9;
  expect_rekeys_below_fraction_of_first_match(relative, 0.9);
}

// The near rule: with the absolute floor above any frame's inliers, the keyframe is kept exactly
// while the camera is within the near radius of it. The arc moves 1.23 cm per frame, so with a
// 3 cm radius frames 1 and 2 are measured against frame 0, frame 3 (3.7 cm) re-keys, and so on.
// Its inlier floor still applies near the keyframe.
TEST(Pipeline, NearKeyframeRuleKeepsTheKeyframeWithinItsRadius) {
  const auto& frames = rendered().frames;
  VoOptions o;
  o.keyframe.min_inliers_to_keep = 1000000;
  o.keyframe.min_inliers_to_keep_near = 1;
  o.keyframe.floor_cap_fraction = 0.0;  // the floors alone (the cap has its own test)
  o.keyframe.near_translation_m = 0.03;
  o.keyframe.near_rotation_rad = 0.05;
  VisualOdometry vo(o);
  vo.process(frames[0]);
  std::vector<size_t> new_references;
  for (size_t k = 1; k < frames.size(); ++k) {
    const VoResult r = vo.process(frames[k]);
    ASSERT_EQ(r.status, VoStatus::kOk) << r.message;
    if (r.new_reference) new_references.push_back(k);
  }
  EXPECT_EQ(new_references, (std::vector<size_t>{3, 6}));

  o.keyframe.min_inliers_to_keep_near = 1000000;
  VisualOdometry strict(o);
  strict.process(frames[0]);
  for (size_t k = 1; k < frames.size(); ++k) {
    EXPECT_TRUE(strict.process(frames[k]).new_reference) << "frame " << k << ": below the near floor";
  }

  o.keyframe.min_inliers_to_keep_near = 1;
  o.keyframe.near_rotation_rad = 0.005;  // the arc turns 0.008 rad per frame
  VisualOdometry turning(o);
  turning.process(frames[0]);
  for (size_t k = 1; k < frames.size(); ++k) {
    EXPECT_TRUE(turning.process(frames[k]).new_reference) << "frame " << k << ": turned beyond the near angle";
  }
}

// The poor-scene cap: with both floors above every frame's inliers (a scene poorer than they
// assume) the VO re-keys at every frame; capped at a share of the keyframe's first match, it
// re-keys exactly when a frame's inliers fall below that share.
TEST(Pipeline, FloorCapKeepsTheKeyframeInAScenePoorerThanTheFloors) {
  const auto& frames = rendered().frames;
  VoOptions o;
  o.keyframe.min_inliers_to_keep = 1000000;
  o.keyframe.min_inliers_to_keep_near = 1000000;
  o.keyframe.floor_cap_fraction = 0.0;
  VisualOdometry uncapped(o);
  uncapped.process(frames[0]);
  for (size_t k = 1; k < frames.size(); ++k)
    EXPECT_TRUE(uncapped.process(frames[k]).new_reference) << "frame " << k << ": below the floors";

  o.keyframe.floor_cap_fraction = 0.9;
  expect_rekeys_below_fraction_of_first_match(o, 0.9);
}

TEST(Pipeline, ResetForgetsTheReference) {
  VisualOdometry vo;
  const auto& frames = rendered().frames;
  vo.process(frames[0]);
  vo.process(frames[1]);
  vo.reset();
  EXPECT_EQ(vo.process(frames[2]).status, VoStatus::kNoReference);
  EXPECT_EQ(vo.process(frames[3]).status, VoStatus::kOk);
}

TEST(Pipeline, EveryVariantFollowsTheTrajectory) {
  for (const Variant& v : variants()) {
    // Absolute orientation alone has no reprojection refinement: looser, as in the paper.
    const bool coarse = v.name == "absolute-orientation" || v.name == "no-subpixel";
    run_and_check(v.options, coarse ? 0.01 : 0.004, coarse ? 0.4 : 0.15, v.name);
  }
}

TEST(Variants, NamesAreUniqueAndUnknownOnesAreRejected) {
  std::set<std::string> names;
  for (const Variant& v : variants()) EXPECT_TRUE(names.insert(v.name).second) << v.name;
  EXPECT_EQ(variants().front().name, "default");
  EXPECT_EQ(variant("ransac").options.inliers.method, InlierMethod::kRansac);
  EXPECT_THROW(variant("nonsense"), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::vo
