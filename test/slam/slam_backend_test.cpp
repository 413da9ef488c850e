// The SLAM back-end on the synthetic room with drifting odometry (known ground truth): loop
// closures cut the trajectory error to a fraction of the odometry's, every accepted closure is
// a true one, a loop-free run closes none, and bad input is refused. Also the odometry chain
// that turns VO updates into poses.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>

#include "common/error.h"
#include "common/geometry/align.h"
#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "slam/backend/odometry_chain.h"
#include "slam/backend/slam.h"
#include "slam/place/builtin_vocabulary.h"
#include "slam/place/frame_features.h"
#include "slam/posegraph/marginals.h"
#include "test/slam/synthetic_room.h"

namespace kestrel::slam {
namespace {

using test::SyntheticRoom;

// The true path corrupted as a drifting odometry would: every step's motion gets a yaw bias
// and random noise, so the error grows with the distance travelled.
std::vector<Eigen::Isometry3d> drifting_odometry(const std::vector<Eigen::Isometry3d>& truth, double yaw_bias_rad,
                                                 double noise_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Isometry3d> odometry{truth.front()};
  for (size_t k = 1; k < truth.size(); ++k) {
    const Eigen::Isometry3d step = truth[k - 1].inverse() * truth[k];
    Vector6d e;
    e << noise_m * n(rng), noise_m * n(rng), noise_m * n(rng), 0.2 * noise_m * n(rng), yaw_bias_rad,
        0.2 * noise_m * n(rng);  // optical y is the vertical: the bias is a yaw
    odometry.push_back(odometry.back() * step * se3::exp(e));
  }
  return odometry;
}

double ate_rmse(const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth) {
  Eigen::Matrix3Xd est(3, static_cast<Eigen::Index>(estimate.size())), gt(3, est.cols());
  for (size_t k = 0; k < estimate.size(); ++k) {
    est.col(static_cast<Eigen::Index>(k)) = estimate[k].translation();
    gt.col(static_cast<Eigen::Index>(k)) = truth[k].translation();
  }
  const Eigen::Isometry3d T = align_rigid(est, gt).value();
  return std::sqrt(((T * est) - gt).colwise().squaredNorm().mean());
}

struct LoopRun {
  std::vector<Eigen::Isometry3d> truth, odometry, optimised;
  int loop_closures = 0;
  int false_closures = 0;
  int64_t last_loop_keyframe = -1;           ///< the reference's keyframe when the last loop closed
  std::optional<Matrix6d> loop_covariance;   ///< Slam::reference_marginal() then
  PoseGraph3d graph;                         ///< at the end
  std::vector<size_t> keyframes;             ///< keyframes made after each frame
  int reanchors = 0;
  int bad_reanchors = 0;                     ///< located more than 2 cm / 1 degree from the truth
  std::vector<size_t> loop_frames;           ///< frames whose keyframe closed a loop
  size_t peak_feature_bytes = 0;             ///< Slam::feature_bytes() at its largest
  int thinned = 0;                           ///< keyframes thinned by the end
};

LoopRun run(const SyntheticRoom& room, const std::vector<Eigen::Isometry3d>& truth, double yaw_bias_rad,
            const SlamOptions& options = {}, std::shared_ptr<const Vocabulary> vocabulary = nullptr) {
  LoopRun r;
  r.truth = truth;
  r.odometry = drifting_odometry(truth, yaw_bias_rad, 0.004, 9);
  Slam slam(options, std::move(vocabulary));
  std::vector<std::pair<int, Eigen::Isometry3d>> placed;  // keyframe, T_keyframe_camera
  for (size_t k = 0; k < truth.size(); ++k) {
    const RgbdFrame frame = room.render(truth[k], test::test_camera(), 1'000'000 + 200'000 * static_cast<int64_t>(k));
    const SlamStep step = slam.add(frame, r.odometry[k]);
    r.peak_feature_bytes = std::max(r.peak_feature_bytes, slam.feature_bytes());
    if (step.loop_closed) {
      ++r.loop_closures;
      r.loop_frames.push_back(k);
      // The reference's keyframe: the new keyframe, or where a loop closed without one put it.
      r.last_loop_keyframe = slam.reference().keyframe_id;
      r.loop_covariance = slam.reference_marginal();
      // The closure's relative pose against the truth: the earlier keyframe's frame and this
      // frame (the new keyframe's, or the frame located without one: CoverageOptions).
      const auto& kfs = slam.keyframes();
      const auto frame_of = [&](int64_t id) { return static_cast<size_t>((kfs[static_cast<size_t>(id)].utime - 1'000'000) / 200'000); };
      const Eigen::Isometry3d true_rel = truth[frame_of(step.loop_keyframe_id)].inverse() * truth[k];
      if (se3::translation_distance(true_rel, step.loop.T_candidate_query) > 0.1 ||
          se3::rotation_distance(true_rel, step.loop.T_candidate_query) > 0.05) {
        ++r.false_closures;
      }
    }
    const auto frame_of = [&](int64_t utime) { return static_cast<size_t>((utime - 1'000'000) / 200'000); };
    if (step.reanchored) {
      ++r.reanchors;
      // Where the frame was put in the keyframe it re-anchored on, against the truth.
      const OdometryReference& ref = slam.reference();
      const size_t kf_frame = frame_of(slam.keyframes()[static_cast<size_t>(ref.keyframe_id)].utime);
      const Eigen::Isometry3d true_rel = truth[kf_frame].inverse() * truth[k];
      if (se3::translation_distance(true_rel, ref.T_keyframe_camera) > 0.02 ||
          se3::rotation_distance(true_rel, ref.T_keyframe_camera) > kPi / 180.0) {
        ++r.bad_reanchors;
      }
    }
    const OdometryReference& ref = slam.reference();
    placed.emplace_back(static_cast<int>(ref.keyframe_id),
                        ref.T_keyframe_camera * ref.T_odom_camera.inverse() * r.odometry[k]);
    r.keyframes.push_back(slam.keyframes().size());
  }
  for (const auto& [kf, T] : placed) r.optimised.push_back(slam.graph().poses[static_cast<size_t>(kf)] * T);
  r.graph = slam.graph();
  r.thinned = slam.num_thinned();
  return r;
}

TEST(Slam, LoopClosureCutsTheDriftOfAClosedLoop) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const LoopRun r = run(room, test::circle_path(60, 1.0, 1.2), 0.006);
  const double vo = ate_rmse(r.odometry, r.truth), slam = ate_rmse(r.optimised, r.truth);
  EXPECT_GT(vo, 0.1) << "the odometry should drift for this test to mean anything";
  EXPECT_LE(slam, 0.3 * vo) << "VO-only ATE " << vo << " m";
  EXPECT_GE(r.loop_closures, 1);
  EXPECT_EQ(r.false_closures, 0);
  std::cout << "ATE: VO only " << vo << " m, SLAM " << slam << " m, " << r.loop_closures << " loop closures\n";

  // The correction's covariance comes from the graph: the loop closures tie the keyframe back
  // to the start, so it is far tighter than what the odometry alone would give it.
  ASSERT_TRUE(r.loop_covariance);
  EXPECT_GT(r.loop_covariance->ldlt().vectorD().minCoeff(), 0.0);
  PoseGraph3d odometry_only = r.graph;
  odometry_only.edges.erase(std::remove_if(odometry_only.edges.begin(), odometry_only.edges.end(),
                                           [](const auto& e) { return e.kind == EdgeKind::kLoopClosure; }),
                            odometry_only.edges.end());
  const auto open = marginal_covariance(odometry_only, static_cast<int>(r.last_loop_keyframe));
  ASSERT_TRUE(open);
  const double closed_m = std::sqrt(r.loop_covariance->topLeftCorner<3, 3>().trace());
  const double open_m = std::sqrt(open->topLeftCorner<3, 3>().trace());
  EXPECT_LT(closed_m, 0.5 * open_m) << "position sigma with loops " << closed_m << " m, odometry only " << open_m << " m";
  std::cout << "newest keyframe position sigma: " << closed_m << " m (odometry only: " << open_m << " m)\n";
}

// Bounded memory (CoverageOptions): three laps of the same circle make the keyframes of about
// one, where without re-anchoring every lap makes its own; every frame located in a covering
// keyframe is where the truth says, and the trajectory is as good as with all the keyframes.
TEST(Slam, LapsOverCoveredGroundAddNoKeyframes) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto laps = test::circle_path(180, 1.0, 3.0);
  // The built-in vocabulary: an online one is retrained as keyframes come, most of the time here.
  const LoopRun reuse = run(room, laps, 0.003, SlamOptions{}, builtin_vocabulary());
  SlamOptions every_lap;
  every_lap.coverage.reuse_keyframes = false;
  const LoopRun grow = run(room, laps, 0.003, every_lap, builtin_vocabulary());
  const size_t first_lap = reuse.keyframes[59];
  std::cout << "keyframes after lap 1: " << first_lap << ", after 3 laps: " << reuse.keyframes.back() << " ("
            << reuse.reanchors << " re-anchorings, " << reuse.loop_closures << " loops); without re-anchoring "
            << grow.keyframes.back() << "\n";
  EXPECT_GE(grow.keyframes.back(), 2 * grow.keyframes[59]) << "every lap should add keyframes without re-anchoring";
  EXPECT_LE(reuse.keyframes.back(), first_lap + first_lap / 5) << "laps over covered ground made keyframes";
  EXPECT_EQ(reuse.keyframes[179], reuse.keyframes[120]) << "the last lap added keyframes";
  EXPECT_GE(reuse.reanchors, 45);
  EXPECT_EQ(reuse.bad_reanchors, 0);
  EXPECT_EQ(reuse.false_closures, 0);
  const double vo = ate_rmse(reuse.odometry, reuse.truth);
  const double with_reuse = ate_rmse(reuse.optimised, reuse.truth), with_all = ate_rmse(grow.optimised, grow.truth);
  std::cout << "ATE: VO " << vo << " m, SLAM re-anchoring " << with_reuse << " m, every keyframe " << with_all << " m\n";
  EXPECT_LE(with_reuse, 0.3 * vo);
  EXPECT_LE(with_reuse, 1.5 * with_all + 0.01);
}

// Bounded memory (KeyframeMemoryOptions): three laps without re-anchoring, every lap making its
// keyframes, under a budget for the features of about one lap's. The features stay within it;
// the thinned keyframes stay in the graph; every place keeps a view, so the last lap still
// closes loops and the trajectory stays as good as with every keyframe matchable.
TEST(Slam, KeyframeFeaturesStayWithinTheirBudgetAndEveryPlaceKeepsAView) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto laps = test::circle_path(180, 1.0, 3.0);
  SlamOptions unbounded;
  unbounded.coverage.reuse_keyframes = false;
  const LoopRun all = run(room, laps, 0.003, unbounded, builtin_vocabulary());
  const size_t lap_keyframes = all.keyframes[59];
  const double per_keyframe = static_cast<double>(all.peak_feature_bytes) / static_cast<double>(all.keyframes.back());
  SlamOptions bounded = unbounded;
  bounded.memory.max_megabytes = 1.2 * static_cast<double>(lap_keyframes) * per_keyframe / 1e6;
  const LoopRun thin = run(room, laps, 0.003, bounded, builtin_vocabulary());
  std::cout << all.keyframes.back() << " keyframes, " << per_keyframe / 1e3 << " kB of features each; budget "
            << bounded.memory.max_megabytes << " MB: " << thin.thinned << " thinned, peak "
            << thin.peak_feature_bytes / 1e6 << " MB, loops " << thin.loop_closures << " (" << all.loop_closures
            << " unbounded)\n";
  EXPECT_EQ(all.thinned, 0);
  EXPECT_LE(static_cast<double>(thin.peak_feature_bytes), bounded.memory.max_megabytes * 1e6);
  EXPECT_EQ(thin.keyframes.back(), all.keyframes.back()) << "thinned keyframes stay in the graph";
  EXPECT_GE(thin.thinned, static_cast<int>(lap_keyframes));
  ASSERT_FALSE(thin.loop_frames.empty());
  EXPECT_GE(thin.loop_frames.back(), 150u) << "the last lap should still find views to close loops with";
  EXPECT_EQ(thin.false_closures, 0);
  EXPECT_LE(ate_rmse(thin.optimised, thin.truth), 1.5 * ate_rmse(all.optimised, all.truth) + 0.01);
}

// A VO restart the estimator bridged still knows where it is: over covered ground it is
// located in the covering keyframe like any frame; a broken one makes a keyframe.
TEST(Slam, ABridgedRestartOverCoveredGroundIsReanchoredAndABrokenOneIsAKeyframe) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto path = test::circle_path(30, 1.0, 0.5);  // half a lap out...
  Slam slam(SlamOptions{}, builtin_vocabulary());
  int64_t utime = 1'000'000;
  for (const auto& T : path) slam.add(room.render(T, test::test_camera(), utime += 200'000), T);
  const size_t keyframes = slam.keyframes().size();
  // ...then back at the start after a VO outage, bridged: located in keyframe 0.
  const SlamStep bridged = slam.add(room.render(path.front(), test::test_camera(), utime += 200'000), path.front(),
                                    OdometryLink::kBridged);
  EXPECT_TRUE(bridged.reanchored);
  EXPECT_EQ(bridged.reanchor_keyframe_id, 0);
  EXPECT_EQ(slam.keyframes().size(), keyframes);
  const SlamStep broken = slam.add(room.render(path[1], test::test_camera(), utime += 200'000), path[1],
                                   OdometryLink::kBroken);
  EXPECT_TRUE(broken.keyframe);
  EXPECT_EQ(slam.keyframes().size(), keyframes + 1);
}

// A frame over covered ground with too few features ever to be located (a blank wall, the dark)
// makes no keyframe: the reference is carried to it at its predicted pose, with no correction to
// send. The same frame where nothing covers it still makes a keyframe (the map needs the pose).
TEST(Slam, AFeaturelessFrameOverCoveredGroundIsCarriedNotAKeyframe) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto path = test::circle_path(30, 1.0, 0.5);
  Slam slam(SlamOptions{}, builtin_vocabulary());
  int64_t utime = 1'000'000;
  for (const auto& T : path) slam.add(room.render(T, test::test_camera(), utime += 200'000), T);
  const size_t keyframes = slam.keyframes().size();
  const int64_t reference_keyframe = slam.reference().keyframe_id;
  RgbdFrame blank;  // no image: no features
  blank.camera = test::test_camera();
  blank.utime = utime += 200'000;
  const SlamStep carried = slam.add(blank, path.front());  // back over keyframe 0
  EXPECT_TRUE(carried.carried);
  EXPECT_TRUE(carried.new_reference());
  EXPECT_FALSE(carried.keyframe || carried.reanchored);
  EXPECT_EQ(slam.keyframes().size(), keyframes);
  EXPECT_EQ(slam.reference().utime, blank.utime);
  EXPECT_EQ(slam.reference().keyframe_id, reference_keyframe) << "carried, not located";
  EXPECT_LT(se3::translation_distance(slam.world_pose(path.front()), path.front()), 1e-9);
  EXPECT_GT(slam.reference().covariance.trace(), 0.0) << "the prediction's uncertainty goes with it";
  EXPECT_EQ(slam.coverage_misses().featureless, 1);
  EXPECT_EQ(slam.reference().link, OdometryLink::kContinuous);
  EXPECT_FALSE(slam.wants_keyframe(path.front())) << "the next try waits for the keyframe spacing";

  // Carried again from the carried frame: the pose composes in the keyframe's frame and the
  // covariance propagates through the adjoint (right perturbations) plus the odometry's own.
  const OdometryReference first = slam.reference();
  blank.utime = utime += 200'000;
  ASSERT_TRUE(slam.add(blank, path[3]).carried);
  const OdometryReference& second = slam.reference();
  EXPECT_EQ(second.keyframe_id, reference_keyframe);
  const Eigen::Isometry3d T_keyframe_truth =
      slam.graph().poses[static_cast<size_t>(reference_keyframe)].inverse() * path[3];
  EXPECT_LT(se3::translation_distance(second.T_keyframe_camera, T_keyframe_truth), 1e-9);
  EXPECT_LT(se3::rotation_distance(second.T_keyframe_camera, T_keyframe_truth), 1e-9);
  const Eigen::Isometry3d T_first_second = path.front().inverse() * path[3];
  const Matrix6d Ad = se3::adjoint(T_first_second.inverse());
  Matrix6d S_inv = Matrix6d::Identity();  // the graph's error of a right perturbation is [rho; phi / 2]
  S_inv.bottomRightCorner<3, 3>() *= 2.0;
  const Matrix6d odometry =
      S_inv * odometry_edge_information(T_first_second, SlamOptions{}.odometry, OdometryLink::kContinuous).inverse() * S_inv;
  const Matrix6d expected = Ad * first.covariance * Ad.transpose() + odometry;
  EXPECT_LT((second.covariance - expected).norm(), 1e-9 * expected.norm()) << second.covariance << "\n" << expected;

  // Carried across a VO restart the estimator bridged: the next keyframe's edge is a bridge's.
  blank.utime = utime += 200'000;
  ASSERT_TRUE(slam.add(blank, path[6], OdometryLink::kBridged).carried);
  EXPECT_EQ(slam.reference().link, OdometryLink::kBridged);
  Eigen::Isometry3d uncovered = path[6];
  uncovered.translation().z() += 0.8;
  blank.utime = utime += 200'000;
  const SlamStep made = slam.add(blank, uncovered);
  EXPECT_TRUE(made.keyframe) << "nothing covers it";
  EXPECT_EQ(slam.keyframes().size(), keyframes + 1);
  EXPECT_EQ(slam.keyframes().back().link, OdometryLink::kBridged) << "as weak as the weakest link since";
}

// A covered frame that no covering keyframe verifies and whose prediction is too uncertain to
// carry (after a VO restart the estimator bridged) is a keyframe, whose loop is searched for;
// but not when it has a few points only, more than a verification needs yet fewer than one is
// likely to find again (a blank wall with an outline in view: CoverageOptions::
// min_points_to_verify): a keyframe of it would hardly ever verify, so it is carried. With the
// bound at 0 the same frame is a keyframe; with all its points, it is a keyframe.
TEST(Slam, AnUnverifiedCoveredFrameWithTooFewPointsForAKeyframeIsCarried) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const SyntheticRoom repainted(6, 3.0, 2.5, 2.5);  // the same room, other texture: nothing verifies
  const auto path = test::circle_path(30, 1.0, 0.5);
  const RgbdFrame full = repainted.render(path.front(), test::test_camera(), 0);
  // The same view with depth kept in a window only: its other keypoints have no point.
  RgbdFrame sparse = full;
  cv::Mat kept = cv::Mat::zeros(full.depth_mm.size(), full.depth_mm.type());
  const cv::Rect window(full.depth_mm.cols / 2 - 15, full.depth_mm.rows / 2 - 15, 30, 30);
  full.depth_mm(window).copyTo(kept(window));
  sparse.depth_mm = kept;
  const SlamOptions defaults;
  const FeatureExtractor extractor(defaults.features);
  const int points = static_cast<int>(extractor.extract(sparse).num_points());
  ASSERT_GE(points, defaults.verification.min_inliers) << "the frame must be verifiable in principle";
  ASSERT_LT(points, defaults.coverage.min_points_to_verify) << "and below the bound";
  ASSERT_GE(static_cast<int>(extractor.extract(full).num_points()), defaults.coverage.min_points_to_verify);

  const auto back_over_keyframe_0 = [&](const RgbdFrame& frame, int bound, Slam::CoverageMisses& misses) {
    SlamOptions options;
    options.coverage.min_points_to_verify = bound;
    Slam slam(options, builtin_vocabulary());
    int64_t utime = 1'000'000;
    for (const auto& T : path) slam.add(room.render(T, test::test_camera(), utime += 200'000), T);
    const size_t keyframes = slam.keyframes().size();
    RgbdFrame f = frame;
    f.utime = utime += 200'000;
    const SlamStep step = slam.add(f, path.front(), OdometryLink::kBridged);
    misses = slam.coverage_misses();
    EXPECT_EQ(slam.keyframes().size(), keyframes + (step.keyframe ? 1 : 0));
    return step;
  };
  Slam::CoverageMisses misses;
  const SlamStep carried = back_over_keyframe_0(sparse, defaults.coverage.min_points_to_verify, misses);
  EXPECT_TRUE(carried.carried) << points << " points";
  EXPECT_FALSE(carried.keyframe || carried.reanchored);
  EXPECT_EQ(misses.few_points_carried, 1);
  EXPECT_EQ(misses.not_verified, 0);
  EXPECT_EQ(misses.featureless, 0) << "tried: " << points << " points are enough to try";

  const SlamStep without = back_over_keyframe_0(sparse, 0, misses);
  EXPECT_TRUE(without.keyframe);
  EXPECT_EQ(misses.not_verified, 1);
  EXPECT_EQ(misses.few_points_carried, 0);

  const SlamStep all_points = back_over_keyframe_0(full, defaults.coverage.min_points_to_verify, misses);
  EXPECT_TRUE(all_points.keyframe);
  EXPECT_EQ(misses.not_verified, 1);
  EXPECT_EQ(misses.few_points_carried, 0);
}

// Back over keyframe 0 after half a lap whose odometry drifted 10 cm: the covering keyframe
// locates the frame beyond the correction bound, a loop. It closes by an edge from keyframe 0 to
// the reference's keyframe, through the frame, with no keyframe added
// (CoverageOptions::close_loops_in_place): the graph moves the drifted keyframes back towards
// the truth and the frame is located in keyframe 0. Not in place, and through a new keyframe as
// before, when the option is off, when keyframe 0 is too recent for a loop
// (LoopSearchOptions::min_age_s), or when the edge disagrees with the odometry (the loop gate).
TEST(Slam, AFrameLocatedTooFarClosesItsLoopWithoutAKeyframe) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto path = test::circle_path(30, 1.0, 0.5);
  const Matrix6d vo_covariance = Matrix6d::Identity() * 1e-6;  // the VO's own, since the reference
  // The odometry drifts along x, a tenth of a metre over the way out.
  const auto odometry = [&](size_t i) {
    Eigen::Isometry3d T = path[i];
    T.translation().x() += 0.1 * static_cast<double>(i) / static_cast<double>(path.size() - 1);
    return T;
  };
  const auto back_at_the_start = [&](const SlamOptions& options, SlamStep& step,
                                      OdometryLink link = OdometryLink::kContinuous) {
    auto slam = std::make_unique<Slam>(options, builtin_vocabulary());
    int64_t utime = 1'000'000;
    for (size_t i = 0; i < path.size(); ++i)
      slam->add(room.render(path[i], test::test_camera(), utime += 200'000), odometry(i));
    Eigen::Isometry3d T_odom = path.front();
    T_odom.translation().x() += 0.1;
    step = slam->add(room.render(path.front(), test::test_camera(), utime += 200'000), T_odom, link,
                     link == OdometryLink::kContinuous ? std::optional<Matrix6d>(vo_covariance) : std::nullopt);
    return slam;
  };
  const auto newest_keyframe_error = [&](const Slam& slam) {
    const Keyframe& kf = slam.keyframes().back();
    size_t best = 0;  // its truth: the path pose whose odometry it was made at
    for (size_t j = 0; j < path.size(); ++j) {
      if (se3::translation_distance(odometry(j), kf.T_odom_camera) <
          se3::translation_distance(odometry(best), kf.T_odom_camera))
        best = j;
    }
    return se3::translation_distance(slam.graph().poses.back(), path[best]);
  };

  SlamStep step;
  {
    SlamOptions no_loop;
    no_loop.coverage.close_loops_in_place = false;
    auto slam = back_at_the_start(no_loop, step);
    EXPECT_TRUE(step.keyframe) << "through a new keyframe";
    EXPECT_TRUE(step.loop_closed);
    EXPECT_EQ(slam->coverage_misses().too_far, 1);
    EXPECT_EQ(slam->coverage_misses().closed_in_place, 0);
  }
  auto slam = back_at_the_start(SlamOptions{}, step);
  const size_t keyframes = slam->keyframes().size();
  EXPECT_FALSE(step.keyframe);
  EXPECT_TRUE(step.loop_closed);
  EXPECT_TRUE(step.reanchored);
  EXPECT_TRUE(step.new_reference());
  EXPECT_EQ(step.loop_keyframe_id, 0);
  EXPECT_EQ(step.reanchor_keyframe_id, 0);
  ASSERT_TRUE(step.optimisation.has_value());
  EXPECT_EQ(slam->coverage_misses().closed_in_place, 1);
  EXPECT_EQ(slam->coverage_misses().too_far, 0);
  EXPECT_EQ(slam->num_loop_closures(), 1);
  EXPECT_EQ(slam->num_inconsistent_loops(), 0);
  EXPECT_EQ(slam->keyframes().size(), keyframes);
  const auto& edge = slam->graph().edges.back();
  EXPECT_EQ(edge.kind, EdgeKind::kLoopClosure);
  EXPECT_EQ(edge.from, 0);
  EXPECT_EQ(edge.to, static_cast<int>(keyframes) - 1) << "to the reference's keyframe, the newest";
  // The frame is where it is, and the drifted keyframes moved back.
  EXPECT_EQ(slam->reference().keyframe_id, 0);
  EXPECT_LT(se3::translation_distance(slam->world_pose(slam->reference().T_odom_camera), path.front()), 0.01);
  EXPECT_LT(newest_keyframe_error(*slam), 0.03) << "10 cm of drift before the loop";

  {  // Keyframe 0 too recent to close a loop with: a keyframe.
    SlamOptions recent;
    recent.loops.min_age_s = 100.0;
    back_at_the_start(recent, step);
    EXPECT_TRUE(step.keyframe);
    EXPECT_FALSE(step.loop_closed) << "no candidate is old enough for the keyframe's own search either";
  }
  {  // The loop gate refuses the edge: a keyframe, whose own loop search finds the same loop and
     // refuses it (counted there only: as many refusals as with the option off, one candidate
     // verified more, the one tried in place).
    SlamOptions strict;
    strict.loop_consistency.sigmas = 1e-3;
    strict.loop_consistency.min_translation_m = 0.01;
    strict.loop_consistency.min_rotation_rad = 0.001;
    auto refused = back_at_the_start(strict, step);
    const SlamStep refused_step = step;
    EXPECT_TRUE(step.keyframe);
    EXPECT_FALSE(step.loop_closed);
    EXPECT_GE(refused->num_inconsistent_loops(), 1);
    EXPECT_EQ(refused->coverage_misses().closed_in_place, 0);
    EXPECT_EQ(refused->coverage_misses().too_far, 1);
    strict.coverage.close_loops_in_place = false;
    auto off = back_at_the_start(strict, step);
    EXPECT_EQ(refused->num_inconsistent_loops(), off->num_inconsistent_loops());
    EXPECT_EQ(refused_step.candidates, step.candidates + 1);
  }
  {  // Across a VO restart the estimator bridged, the odometry to the frame is uncertain (5 cm
     // floors): the edge is weak and the keyframes hardly move, but the frame is located all
     // the same, where it is.
    auto bridged = back_at_the_start(SlamOptions{}, step, OdometryLink::kBridged);
    EXPECT_FALSE(step.keyframe);
    EXPECT_TRUE(step.loop_closed);
    EXPECT_TRUE(step.reanchored);
    EXPECT_EQ(bridged->reference().keyframe_id, 0);
    EXPECT_LT(se3::translation_distance(bridged->world_pose(bridged->reference().T_odom_camera), path.front()), 0.01);
    EXPECT_GT(newest_keyframe_error(*bridged), 0.03) << "a weak edge should hardly move the keyframes";
  }
}

// A covered frame that no covering keyframe verifies (here: the same pose in a room of other
// texture) is carried at its predicted pose while that prediction is certain and made from a
// neighbouring keyframe (CoverageOptions::carry_within_sigmas). It is a keyframe, whose loop is
// searched for, when the odometry is uncertain (a VO restart the estimator bridged: 3 sigmas of
// the bridge's 5 cm floor exceed the 5 cm correction bound) or when the graph does not relate the
// reference's keyframe to the covering ones (a revisit after a long way round, where the world
// estimate may have drifted).
TEST(Slam, AnUnverifiedCoveredFrameIsCarriedWhileItsPredictionIsCertainAndLocal) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const SyntheticRoom repainted(6, 3.0, 2.5, 2.5);
  const auto path = test::circle_path(30, 1.0, 0.5);
  // The VO's own covariance of the motion since the reference: a few millimetres.
  const Matrix6d vo_covariance = Matrix6d::Identity() * 1e-5;
  const auto fly_out = [&](Slam& slam, int64_t& utime) {
    for (const auto& T : path) slam.add(room.render(T, test::test_camera(), utime += 200'000), T);
  };

  {  // Back the way it came: located in the keyframes of the way out, then a repainted view.
    Slam slam(SlamOptions{}, builtin_vocabulary());
    int64_t utime = 1'000'000;
    fly_out(slam, utime);
    const size_t keyframes = slam.keyframes().size();
    size_t k = path.size() - 1;
    bool located = false;
    while (!located && k-- > 0)
      located = slam.add(room.render(path[k], test::test_camera(), utime += 200'000), path[k], OdometryLink::kContinuous,
                         vo_covariance).reanchored;
    ASSERT_TRUE(located) << "the way back should be located in the way out's keyframes";
    SlamStep tried;
    while (!tried.new_reference() && k-- > 0)
      tried = slam.add(repainted.render(path[k], test::test_camera(), utime += 200'000), path[k],
                       OdometryLink::kContinuous, vo_covariance);
    ASSERT_TRUE(tried.new_reference()) << "a frame of the way back should have been tried";
    EXPECT_TRUE(tried.carried);
    EXPECT_FALSE(tried.keyframe || tried.reanchored);
    EXPECT_EQ(slam.keyframes().size(), keyframes);
    EXPECT_EQ(slam.coverage_misses().unverified_carried, 1);
    EXPECT_EQ(slam.coverage_misses().not_verified, 0);
    EXPECT_EQ(slam.coverage_misses().featureless, 0) << "it has features, they just do not match";

    // The next, after a VO restart the estimator bridged: too uncertain to carry.
    SlamStep bridged;
    while (!bridged.new_reference() && k-- > 0)
      bridged = slam.add(repainted.render(path[k], test::test_camera(), utime += 200'000), path[k],
                         OdometryLink::kBridged);
    EXPECT_TRUE(bridged.keyframe);
    EXPECT_EQ(slam.keyframes().size(), keyframes + 1);
    EXPECT_EQ(slam.coverage_misses().not_verified, 1);
    EXPECT_EQ(slam.coverage_misses().unverified_carried, 1);
  }
  {  // Round a whole circle back to its start: 18 degrees from the reference's keyframe, whose
     // odometry may have drifted since the start's keyframe, which alone covers the view.
    const auto circle = test::circle_path(40, 1.0, 1.0);
    Slam slam(SlamOptions{}, builtin_vocabulary());
    int64_t utime = 1'000'000;
    for (size_t k = 0; k + 2 < circle.size(); ++k)
      slam.add(room.render(circle[k], test::test_camera(), utime += 200'000), circle[k], OdometryLink::kContinuous,
               vo_covariance);
    const SlamStep revisit = slam.add(repainted.render(circle.back(), test::test_camera(), utime += 200'000),
                                      circle.back(), OdometryLink::kContinuous, vo_covariance);
    EXPECT_TRUE(revisit.keyframe) << "a revisit the graph does not relate to the reference searches for its loop";
    EXPECT_EQ(slam.coverage_misses().not_verified, 1);
    EXPECT_EQ(slam.coverage_misses().unverified_carried, 0);
  }
  {  // Off: the same way back makes a keyframe.
    SlamOptions never;
    never.coverage.carry_within_sigmas = 0.0;
    Slam slam(never, builtin_vocabulary());
    int64_t utime = 1'000'000;
    fly_out(slam, utime);
    size_t k = path.size() - 1;
    bool located = false;
    while (!located && k-- > 0)
      located = slam.add(room.render(path[k], test::test_camera(), utime += 200'000), path[k], OdometryLink::kContinuous,
                         vo_covariance).reanchored;
    SlamStep tried;
    while (!tried.new_reference() && k-- > 0)
      tried = slam.add(repainted.render(path[k], test::test_camera(), utime += 200'000), path[k],
                       OdometryLink::kContinuous, vo_covariance);
    EXPECT_TRUE(tried.keyframe);
    EXPECT_EQ(slam.coverage_misses().not_verified, 1);
    EXPECT_EQ(slam.coverage_misses().unverified_carried, 0);
  }
}

// After a break of the odometry nothing bridged, the new odometry is placed in the map only by
// a loop to a keyframe from before the break (Slam::odometry_placed()): a loop among the
// keyframes made since relates them to each other, not to the map. Here the flight after the
// break goes round a repainted room (nothing in it matches the first room's keyframes), closes
// its own loop, and is placed only back in the first room.
TEST(Slam, OnlyALoopToAKeyframeFromBeforeABreakPlacesTheOdometry) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const SyntheticRoom repainted(6, 3.0, 2.5, 2.5);
  const auto half = test::circle_path(30, 1.0, 0.5);
  const auto circle = test::circle_path(40, 1.0, 1.0);
  Slam slam(SlamOptions{}, builtin_vocabulary());
  int64_t utime = 1'000'000;
  for (const auto& T : half) slam.add(room.render(T, test::test_camera(), utime += 200'000), T);
  EXPECT_TRUE(slam.odometry_placed());
  const size_t before_break = slam.keyframes().size();
  // The break: the new odometry starts again from identity, wherever the camera is.
  const Eigen::Isometry3d T_odom_world = circle.front().inverse();
  slam.add(repainted.render(circle.front(), test::test_camera(), utime += 200'000), T_odom_world * circle.front(),
           OdometryLink::kBroken);
  EXPECT_FALSE(slam.odometry_placed());
  int own_loops = 0;
  for (size_t k = 1; k < circle.size(); ++k) {
    const SlamStep step = slam.add(repainted.render(circle[k], test::test_camera(), utime += 200'000),
                                   T_odom_world * circle[k]);
    if (step.loop_closed) {
      EXPECT_GE(step.loop_keyframe_id, static_cast<int64_t>(before_break)) << "the repainted room matches only itself";
      ++own_loops;
    }
  }
  ASSERT_GT(own_loops, 0) << "the circle should close its own loop";
  EXPECT_FALSE(slam.odometry_placed()) << "a loop among the keyframes since the break places nothing";
  // Back in the first room, where the map was made before the break.
  bool placed = false;
  for (size_t k = 0; k < half.size() && !placed; ++k) {
    const SlamStep step =
        slam.add(room.render(half[k], test::test_camera(), utime += 200'000), T_odom_world * half[k]);
    if (step.loop_closed && step.loop_keyframe_id < static_cast<int64_t>(before_break)) placed = true;
  }
  ASSERT_TRUE(placed) << "the first room's keyframes should close a loop";
  EXPECT_TRUE(slam.odometry_placed());
}

// A VO lost while the camera lingers (a hover over a blank patch, a fast turn and back): the
// keyframes from just before the break are younger than the loops' minimum age (4 s), yet
// across a break nothing placed they are no odometry neighbours, so a loop to them places the
// new odometry at once; before, it waited until they were 4 s old. Along a wall every place
// is seen once, so no older keyframe can do it here.
TEST(Slam, AnOdometryBreakIsPlacedAtOnceByTheKeyframesJustBeforeIt) {
  const SyntheticRoom room(5, 7.0, 1.5, 2.5);
  const auto path = test::straight_path(40, 12.0);
  Slam slam(SlamOptions{}, builtin_vocabulary());
  int64_t utime = 1'000'000;
  for (int k = 0; k < 20; ++k) slam.add(room.render(path[k], test::test_camera(), utime += 200'000), path[k]);
  ASSERT_TRUE(slam.odometry_placed());
  const auto before_break = static_cast<int64_t>(slam.keyframes().size());
  const int64_t last_keyframe_utime = slam.keyframes().back().utime;
  // The break at frame 20: the new odometry starts again from identity.
  const Eigen::Isometry3d T_odom_world = path[20].inverse();
  int placed_at = -1;
  SlamStep placing;
  for (int k = 20; k < 26 && placed_at < 0; ++k) {
    const SlamStep step = slam.add(room.render(path[k], test::test_camera(), utime += 200'000), T_odom_world * path[k],
                                   k == 20 ? OdometryLink::kBroken : OdometryLink::kContinuous);
    if (slam.odometry_placed()) placed_at = k, placing = step;
  }
  ASSERT_GE(placed_at, 0) << "no loop to the keyframes just before the break";
  EXPECT_LE(placed_at, 22);
  ASSERT_TRUE(placing.loop_closed);
  ASSERT_LT(placing.loop_keyframe_id, before_break);
  const auto& loop_keyframe = slam.keyframes()[static_cast<size_t>(placing.loop_keyframe_id)];
  EXPECT_LT(slam.keyframes().back().utime - loop_keyframe.utime, 4'000'000) << "younger than the loops' minimum age";
  EXPECT_LE(loop_keyframe.utime, last_keyframe_utime);
  // Placed where it is: the newest keyframe at the truth (the map's world is the first odometry's).
  EXPECT_LT(se3::translation_distance(slam.graph().poses.back(), path[static_cast<size_t>(placed_at)]), 0.02);
  // Once placed, the minimum age holds again: on along the wall (neighbouring keyframes see
  // overlapping strips of it), no further loop.
  for (int k = placed_at + 1; k < 40; ++k)
    slam.add(room.render(path[k], test::test_camera(), utime += 200'000), T_odom_world * path[k]);
  EXPECT_EQ(slam.num_loop_closures(), 1);
}

TEST(Slam, ALoopFreeRunClosesNoLoop) {
  const SyntheticRoom room(5, 7.0, 1.5, 2.5);
  const LoopRun r = run(room, test::straight_path(40, 12.0), 0.004);
  EXPECT_EQ(r.loop_closures, 0);
  // Without loops the optimised poses are the odometry's.
  for (size_t k = 0; k < r.odometry.size(); ++k) {
    EXPECT_LT(se3::translation_distance(r.optimised[k], r.odometry[k]), 1e-9);
  }
}

TEST(Slam, MakesKeyframesEvery25CmOr10Degrees) {
  Slam slam;
  RgbdFrame frame;  // no image: keyframes without features
  frame.camera = test::test_camera();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int k = 0; k < 20; ++k) {
    frame.utime = 1000 + k;
    T.translation().z() = 0.1 * k;  // 10 cm per frame: a keyframe every third frame
    slam.add(frame, T);
  }
  ASSERT_EQ(slam.keyframes().size(), 7u);
  EXPECT_NEAR(slam.keyframes()[1].T_odom_camera.translation().z(), 0.3, 1e-12);
  EXPECT_TRUE(slam.wants_keyframe(T * se3::exp((Vector6d() << 0, 0, 0, 0, 0.18, 0).finished())));
  EXPECT_FALSE(slam.wants_keyframe(T * se3::exp((Vector6d() << 0.1, 0, 0, 0, 0.16, 0).finished())));
  EXPECT_EQ(slam.graph().num_edges(), 6);
  // A restart of the odometry always makes a keyframe, which keeps how it relates to the last.
  frame.utime = 2000;
  slam.add(frame, Eigen::Isometry3d::Identity(), OdometryLink::kBroken);
  ASSERT_EQ(slam.keyframes().size(), 8u);
  EXPECT_EQ(slam.keyframes().back().link, OdometryLink::kBroken);
  EXPECT_EQ(slam.keyframes()[1].link, OdometryLink::kContinuous);
}

TEST(Slam, RefusesTimeGoingBackAndPosesThatAreNotRigid) {
  Slam slam;
  RgbdFrame frame;
  frame.utime = 100;
  slam.add(frame, Eigen::Isometry3d::Identity());
  frame.utime = 100;
  EXPECT_THROW(slam.add(frame, Eigen::Isometry3d::Identity()), InputError);
  frame.utime = 200;
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_THROW(slam.add(frame, bad), InputError);
  EXPECT_FALSE(slam.wants_keyframe(bad));
  EXPECT_EQ(slam.keyframes().size(), 1u);
}

VoMotion motion(int64_t utime, int64_t reference, bool ok, bool new_reference, double x = 0.0) {
  VoMotion m;
  m.utime = utime;
  m.reference_utime = reference;
  m.ok = ok;
  m.new_reference = new_reference;
  m.T_reference_current.translation().x() = x;
  return m;
}

TEST(OdometryChain, ChainsMotionsThroughReferencesAndFlagsRestarts) {
  OdometryChain chain;
  auto x = [](const std::optional<OdometryPose>& p) { return p.value().T_odom_camera.translation().x(); };
  auto first = chain.add(motion(10, 0, false, true));  // first frame: the reference
  ASSERT_TRUE(first.has_value());
  EXPECT_FALSE(first->broken);
  EXPECT_NEAR(x(chain.add(motion(20, 10, true, false, 0.1))), 0.1, 1e-12);
  EXPECT_NEAR(x(chain.add(motion(30, 10, true, true, 0.3))), 0.3, 1e-12);  // the new reference
  EXPECT_NEAR(x(chain.add(motion(40, 30, true, false, 0.2))), 0.5, 1e-12);
  EXPECT_FALSE(chain.add(motion(50, 30, false, false)).has_value());  // a failed frame: no pose
  const auto restart = chain.add(motion(60, 0, false, true));  // the odometry restarted
  ASSERT_TRUE(restart.has_value());
  EXPECT_TRUE(restart->broken);
  EXPECT_NEAR(x(restart), 0.5, 1e-12) << "a restart continues from the last pose";
  const auto next = chain.add(motion(70, 60, true, false, 0.1));
  ASSERT_TRUE(next.has_value());
  EXPECT_FALSE(next->broken);
  EXPECT_NEAR(x(next), 0.6, 1e-12);
}

// A motion that turns and moves, with a covariance: what the chain does to it shows in every axis.
VoMotion turning(int64_t utime, int64_t reference, bool ok, bool new_reference, double k) {
  VoMotion m = motion(utime, reference, ok, new_reference);
  m.T_reference_current = se3::exp((Vector6d() << 0.1 * k, -0.05 * k, 0.02 * k, 0.03 * k, 0.1 * k, -0.02 * k).finished());
  m.T_body_camera = se3::exp((Vector6d() << 0.1, 0.0, 0.05, -1.2, 0.0, -1.5).finished());
  m.covariance = Matrix6d::Identity() * 1e-4 * k;
  m.covariance(0, 4) = m.covariance(4, 0) = 2e-5 * k;
  return m;
}

// A reference whose announcement never reached SLAM (lost on a lossy link, the first frame's
// included): the first motion against it starts a segment, and within it the chain is what it
// would have been with the announcement (the same relative poses and covariances). Before,
// every motion against it had no pose for as long as the VO kept that reference (a hover: the
// whole flight).
TEST(OdometryChain, AMotionAgainstAReferenceItNeverSawStartsASegmentTheNextOnesChainOn) {
  OdometryChain lossless, lossy;
  ASSERT_TRUE(lossless.add(turning(10, 0, false, true, 0)).has_value());  // the first frame, lost on the link
  const int64_t utimes[] = {20, 30, 40};
  std::vector<OdometryPose> a, b;
  for (int64_t t : utimes) {
    const VoMotion m = turning(t, 10, true, t == 40, static_cast<double>(t) / 10.0);
    a.push_back(lossless.add(m).value());
    b.push_back(lossy.add(m).value());
  }
  EXPECT_FALSE(b[0].broken) << "nothing came before it";
  EXPECT_TRUE(b[0].T_odom_camera.isApprox(turning(20, 0, false, true, 0).T_body_camera, 1e-12))
      << "the first pose is the mounting's, as for a first frame";
  for (size_t i = 1; i < a.size(); ++i) {
    EXPECT_FALSE(b[i].broken);
    EXPECT_TRUE((b[0].T_odom_camera.inverse() * b[i].T_odom_camera)
                    .isApprox(a[0].T_odom_camera.inverse() * a[i].T_odom_camera, 1e-12));
    const auto ca = lossless.relative_covariance(a[0], a[i]), cb = lossy.relative_covariance(b[0], b[i]);
    ASSERT_TRUE(ca && cb);
    EXPECT_TRUE(cb->isApprox(*ca, 1e-12)) << *cb << "\nagainst\n" << *ca;
  }
  // Later the announcement of reference 50 is lost; 60 and 70 are measured from it.
  const auto p60 = lossy.add(turning(60, 50, true, false, 2.0));
  ASSERT_TRUE(p60.has_value());
  EXPECT_TRUE(p60->broken) << "not related to the poses before";
  EXPECT_TRUE(p60->T_odom_camera.isApprox(b.back().T_odom_camera, 1e-12)) << "a new segment starts at the last pose";
  const auto p70 = lossy.add(turning(70, 50, true, false, 3.0));
  ASSERT_TRUE(p70.has_value());
  EXPECT_FALSE(p70->broken);
  EXPECT_TRUE((p60->T_odom_camera.inverse() * p70->T_odom_camera)
                  .isApprox(turning(60, 50, true, false, 2.0).T_reference_current.inverse() *
                                turning(70, 50, true, false, 3.0).T_reference_current,
                            1e-12));
  EXPECT_TRUE(lossy.relative_covariance(*p60, *p70).has_value()) << "one segment";
  EXPECT_FALSE(lossy.relative_covariance(b[1], *p70).has_value()) << "across the break";
  EXPECT_FALSE(lossy.add(motion(80, 50, false, false)).has_value()) << "a failed frame still has none";
}

// The VO falls back to the previous frame when its keyframe fails: a motion from a frame no
// update announced, whose pose the chain gave. It chains on through that frame, no break, as if
// the frame had been announced (it was a break before: a SLAM keyframe at every fall-back).
TEST(OdometryChain, AFallBackToThePreviousFrameChainsOnThroughItWithoutABreak) {
  OdometryChain announced, fell_back;
  for (OdometryChain* c : {&announced, &fell_back}) ASSERT_TRUE(c->add(turning(10, 0, false, true, 0)).has_value());
  std::vector<OdometryPose> a, b;
  for (int64_t t : {20, 30}) {
    a.push_back(announced.add(turning(t, 10, true, t == 30, static_cast<double>(t) / 10.0)).value());
    b.push_back(fell_back.add(turning(t, 10, true, false, static_cast<double>(t) / 10.0)).value());
  }
  const VoMotion fall_back = turning(40, 30, true, true, 1.5);  // measured from 30, the frame before
  a.push_back(announced.add(fall_back).value());
  b.push_back(fell_back.add(fall_back).value());
  EXPECT_FALSE(b.back().broken);
  EXPECT_TRUE(b.back().T_odom_camera.isApprox(a.back().T_odom_camera, 1e-12));
  const auto ca = announced.relative_covariance(a[0], a.back()), cb = fell_back.relative_covariance(b[0], b.back());
  ASSERT_TRUE(ca && cb);
  EXPECT_TRUE(cb->isApprox(*ca, 1e-12));
}

TEST(OdometryChain, AMotionFromAFrameThatIsNotEarlierIsAnInputError) {
  OdometryChain chain;
  chain.add(motion(10, 0, false, true));
  EXPECT_THROW(chain.add(motion(20, 0, true, false, 0.1)), InputError);   // no reference
  EXPECT_THROW(chain.add(motion(30, 30, true, false, 0.1)), InputError);  // itself
  EXPECT_THROW(chain.add(motion(40, 50, true, false, 0.1)), InputError);  // a later frame
  EXPECT_NEAR(chain.add(motion(60, 10, true, false, 0.1)).value().T_odom_camera.translation().x(), 0.1, 1e-12);
}

TEST(OdometryChain, RefusesTimeGoingBackAndNonRigidMotion) {
  OdometryChain chain;
  chain.add(motion(10, 0, false, true));
  EXPECT_THROW(chain.add(motion(10, 10, true, false)), InputError);
  VoMotion bad = motion(20, 10, true, false);
  bad.T_reference_current.linear() *= 2.0;
  EXPECT_THROW(chain.add(bad), InputError);
}

}  // namespace
}  // namespace kestrel::slam
