// The offline engine (vo/sequence_run.h) on runs that estimated nothing or only part of a
// sequence: no accuracy figures without a motion (never zeros, which read as a perfect run),
// the frames counted by status, and require_usable() refusing a run with no motion in one
// line that names the folder, the counts and the first failure.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "common/error.h"
#include "test/vo/synthetic_scene.h"
#include "test/vo/synthetic_tum.h"
#include "vo/sequence_run.h"

namespace kestrel::vo::sequence_run_test {  // named: the unity batch holds pipeline_test.cpp too
namespace {

constexpr int64_t kT0 = 1000000;
constexpr int64_t kPeriod = 33333;

// n frames of the synthetic room along its line; the frames in [blank_from, n) have no depth at all.
std::vector<RgbdFrame> frames(int n, int blank_from) {
  static const test::SyntheticScene scene(17);
  std::vector<RgbdFrame> out;
  for (int k = 0; k < n; ++k) {
    out.push_back(scene.render(test::line_pose(k), test::test_camera(), kT0 + kPeriod * k));
    if (k >= blank_from) out.back().depth_mm.setTo(cv::Scalar::all(0));
  }
  return out;
}

// World = the first camera, as the run's trajectory.
Trajectory ground_truth(int n) { return test::line_ground_truth(kT0, kPeriod, n); }

size_t count(const RunFigures& f, VoStatus s) { return f.by_status[size_t(s)]; }

TEST(SequenceRun, NoValidDepthAnywhereMeasuresNothingAndIsRefused) {
  const SequenceRun run = run_sequence(frames(4, 0), VoOptions{});
  const RunFigures f = score(run, ground_truth(4));
  EXPECT_EQ(f.frames, 4u);
  EXPECT_EQ(f.ok, 0u);
  EXPECT_EQ(count(f, VoStatus::kInsufficientDepth), 4u);
  EXPECT_FALSE(f.scored);
  EXPECT_EQ(f.not_scored, "no frame has a motion");
  EXPECT_EQ(f.ate_rmse_m, 0.0);  // not measured: the JSON says null, not 0
  const nlohmann::json j = nlohmann::json::parse(stats_json(run, f, "default"));
  EXPECT_TRUE(j.at("accuracy").is_null());
  EXPECT_EQ(j.at("not_scored"), "no frame has a motion");
  EXPECT_EQ(j.at("by_status").at("too little valid depth"), 4);
  try {
    require_usable(run.results, "/data/zero_depth");
    FAIL() << "a run without a single motion was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("/data/zero_depth: nothing usable: 0 of 4 frames gave a motion (too little valid depth 4)", 0),
              0u)
        << what;
    EXPECT_NE(what.find("first failure at 1.000000 s: too little valid depth"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(SequenceRun, ASingleFrameHasNoMotionAndIsRefused) {
  const SequenceRun run = run_sequence(frames(1, 1), VoOptions{});
  const RunFigures f = score(run, ground_truth(1));
  EXPECT_EQ(count(f, VoStatus::kNoReference), 1u);
  EXPECT_FALSE(f.scored);
  EXPECT_EQ(run.trajectory.size(), 1u);  // the reference's identity pose, which alone scores 0
  EXPECT_THROW(require_usable(run.results, "one"), InputError);
}

TEST(SequenceRun, NoFramesAtAllIsRefused) {
  const SequenceRun run = run_sequence({}, VoOptions{});
  const RunFigures f = score(run, ground_truth(1));
  EXPECT_FALSE(f.scored);
  EXPECT_EQ(status_summary(f), "no frames");
  EXPECT_THROW(require_usable(run.results, "none"), InputError);
}

TEST(SequenceRun, APartlyUsableRunIsScoredAndCountsTheFramesByStatus) {
  const SequenceRun run = run_sequence(frames(8, 5), VoOptions{});
  const RunFigures f = score(run, ground_truth(8));
  EXPECT_EQ(f.frames, 8u);
  EXPECT_EQ(f.ok, 4u);
  EXPECT_EQ(count(f, VoStatus::kNoReference), 1u);
  EXPECT_EQ(count(f, VoStatus::kInsufficientDepth), 3u);
  EXPECT_EQ(status_summary(f), "ok 4, no reference 1, too little valid depth 3");
  EXPECT_NO_THROW(require_usable(run.results, "partial"));
  ASSERT_TRUE(f.scored) << f.not_scored;
  EXPECT_EQ(f.scored_frames, 5u);  // the reference and the four motions
  EXPECT_LT(f.ate_rmse_m, 0.01);
  EXPECT_EQ(f.gross, 3u);  // the frames without an estimate
}

TEST(SequenceRun, WithoutGroundTruthNothingIsScoredButTheRunIsUsable) {
  const SequenceRun run = run_sequence(frames(3, 3), VoOptions{});
  const RunFigures f = score(run, Trajectory{});
  EXPECT_EQ(f.ok, 2u);
  EXPECT_FALSE(f.scored);
  EXPECT_EQ(f.not_scored, "no ground truth");
  EXPECT_NO_THROW(require_usable(run.results, "no_gt"));
}

TEST(SequenceRun, GroundTruthThatCoversNoEstimateIsNotScored) {
  const SequenceRun run = run_sequence(frames(3, 3), VoOptions{});
  Trajectory later;  // an hour after the frames
  for (int i = 0; i < 10; ++i) later.push_back(kT0 + 3600000000LL + 10000 * i, Eigen::Isometry3d::Identity());
  const RunFigures f = score(run, later);
  EXPECT_EQ(f.ok, 2u);
  EXPECT_FALSE(f.scored);
  EXPECT_FALSE(f.not_scored.empty());
}

}  // namespace
}  // namespace kestrel::vo::sequence_run_test
