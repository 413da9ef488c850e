// The estimator's tools as a user runs them: kestrel-estimate, kestrel-fit-vo-noise and
// kestrel-hold on synthesised logs, their usage errors and exit codes, and kestrel-estimator's
// --help.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/trajectory.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/estimator/synthetic_log.h"
#include "test/support/test_support.h"

namespace kestrel::estimator {
namespace {

namespace ts = kestrel::test;

TEST(EstimateTool, WritesTheTrajectoryWithEitherFilter) {
  ts::TempDir dir;
  const std::string log = (dir / "still.lcmlog").string();
  test::write_log(log, 3.0, true);
  for (const char* filter : {"ekf", "ukf"}) {
    const std::string out = (dir / (std::string(filter) + ".txt")).string();
    const auto r = ts::run({ts::tool("estimate"), "--log", log, "--out", out, "--filter", filter,
                            "--init-yaw", "0.3"});
    ASSERT_EQ(r.exit_code, kExitOk) << r.err;
    EXPECT_NE(r.out.find("messages skipped: 2"), std::string::npos) << r.out;
    const Trajectory t = read_tum_trajectory(out);
    ASSERT_GT(t.size(), 400u);  // 200 Hz after the 0.5 s still start
    EXPECT_LT(t.poses().back().T.translation().norm(), 0.03) << filter;
  }
}

TEST(EstimateTool, UsageAndInputErrorsHaveTheirExitCodes) {
  ts::TempDir dir;
  EXPECT_EQ(ts::run({ts::tool("estimate"), "--help"}).exit_code, kExitOk);
  EXPECT_EQ(ts::run({ts::tool("estimator"), "--help"}).exit_code, kExitOk);
  EXPECT_EQ(ts::run({ts::tool("estimate")}).exit_code, kExitUsage);
  const std::string log = (dir / "still.lcmlog").string();
  test::write_log(log, 1.0, false);
  const std::string out = (dir / "t.txt").string();
  EXPECT_EQ(ts::run({ts::tool("estimate"), "--log", log, "--out", out, "--filter", "kalman"}).exit_code,
            kExitUsage);
  EXPECT_EQ(ts::run({ts::tool("estimate"), "--log", log, "--out", out, "--vo-sigma", "1,2"}).exit_code,
            kExitUsage);
  // A file that is not an LCM log, and a log without IMU: bad input, naming the file.
  const std::string text = (dir / "notes.txt").string();
  { std::FILE* f = std::fopen(text.c_str(), "w"); std::fputs("not a log\n", f); std::fclose(f); }
  auto r = ts::run({ts::tool("estimate"), "--log", text, "--out", out});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  const std::string empty = (dir / "empty.lcmlog").string();
  { transport::LogWriter w(empty); w.write("OTHER", 1, {1, 2}); w.close(); }
  r = ts::run({ts::tool("estimate"), "--log", empty, "--out", out});
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("IMU"), std::string::npos) << r.err;
}

TEST(FitVoNoiseTool, PrintsTheFittedModelAsEstimatorOptions) {
  ts::TempDir dir;
  const std::string log = (dir / "still.lcmlog").string();
  test::write_log(log, 4.0, false, true);
  const auto r = ts::run({ts::tool("fit-vo-noise"), "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("--vo-noise constant --vo-sigma "), std::string::npos) << r.out;
  const std::string no_truth = (dir / "no_truth.lcmlog").string();
  test::write_log(no_truth, 1.0, false, false);
  EXPECT_EQ(ts::run({ts::tool("fit-vo-noise"), "--log", no_truth}).exit_code, kExitBadInput);
}

// kestrel-hold on a hand-made log: truth at 0, 0.5 and 1 s (3-4-5 triangles: 5 cm horizontal,
// then 12 cm up as well, 13 cm 3D), STATE from 0.5 s (one INITIALIZING before it, not usable).
TEST(HoldTool, ScoresTruthFromTargetAndStateFromTruth) {
  ts::TempDir dir;
  const std::string log = (dir / "hold.lcmlog").string(), truth_only = (dir / "truth.lcmlog").string();
  auto pose = [](double x, double y, double z, double yaw) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << x, y, z;
    T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return transport::to_message(T);
  };
  auto truth = [&](int64_t utime, double x, double y, double z) {
    kestrel::ground_truth_t m{};
    m.utime = utime;
    m.frame = kestrel::ground_truth_t::FRAME_BODY;
    m.T_world_frame = pose(x, y, z, 0.5);
    return m;
  };
  auto state = [&](int64_t utime, int8_t status, double x, double y, double z) {
    kestrel::state_t m{};
    m.utime = utime;
    m.status = status;
    m.T_world_body = pose(x, y, z, 0.5);
    return m;
  };
  {
    transport::LogWriter w(log), t(truth_only);
    const std::vector<kestrel::ground_truth_t> gt{truth(1000000, 1, 2, 3), truth(1500000, 1.03, 2.04, 3),
                                                  truth(2000000, 1.03, 2.04, 3.12)};
    for (const auto& m : gt) {
      w.write_message(channel::kGroundTruth, m.utime, m);
      t.write_message(channel::kGroundTruth, m.utime, m);
    }
    w.write_message(channel::kState, 1200000, state(1200000, kestrel::state_t::STATUS_INITIALIZING, 0, 0, 0));
    w.write_message(channel::kState, 1500000, state(1500000, kestrel::state_t::STATUS_OK, 1, 2, 3));
    w.write_message(channel::kState, 2000000, state(2000000, kestrel::state_t::STATUS_DEGRADED, 1.03, 2.04, 3.12));
    // Three motions from two references (inliers 250, 180, 320: median 250) and a failure.
    const std::vector<std::array<int64_t, 4>> vo{{1100000, 1000000, 250, kestrel::vo_update_t::STATUS_OK},
                                                 {1200000, 1000000, 180, kestrel::vo_update_t::STATUS_OK},
                                                 {1300000, 1200000, 320, kestrel::vo_update_t::STATUS_OK},
                                                 {1400000, 0, 0, kestrel::vo_update_t::STATUS_INSUFFICIENT_INLIERS}};
    for (const auto& [utime, reference, inliers, status] : vo) {
      kestrel::vo_update_t m{};
      m.utime = utime;
      m.reference_utime = reference;
      m.num_reprojection_inliers = static_cast<int32_t>(inliers);
      m.status = static_cast<int8_t>(status);
      m.T_reference_current = transport::to_message(Eigen::Isometry3d::Identity());
      w.write_message(channel::kVoUpdate, utime, m);
    }
    w.close();
    t.close();
  }
  auto r = ts::run({ts::tool("hold"), "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  for (const char* want : {"flying on STATE from 0.50 s; scored 0.50 to 1.00 s",
                           "STATE: 3 messages, 2 usable, 1 of them DEGRADED; VO_UPDATE: 4 (3 OK)",
                           "VO: motions from 2 reference frames, median 250 inliers",
                           "truth from target, horizontal: mean   5.0 cm, max   5.0 cm",
                           "truth from target, 3D:         mean   9.0 cm, max  13.0 cm",
                           "truth vs STATE, horizontal: mean   2.5 cm, max   5.0 cm",
                           "truth vs STATE, 3D:         mean   2.5 cm, max   5.0 cm",
                           "yaw error: mean 0.00 deg, max 0.00 deg"})
    EXPECT_NE(r.out.find(want), std::string::npos) << want << "\n" << r.out;

  // --truth-only scores the truth alone, from the first sample unless --from says otherwise.
  r = ts::run({ts::tool("hold"), "--log", truth_only, "--truth-only"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("horizontal: mean   3.3 cm, max   5.0 cm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3D:         mean   6.0 cm, max  13.0 cm"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("STATE"), std::string::npos) << r.out;
  r = ts::run({ts::tool("hold"), "--log", truth_only, "--truth-only", "--from", "0.5"});
  EXPECT_NE(r.out.find("3D:         mean   9.0 cm, max  13.0 cm"), std::string::npos) << r.out;

  // Without usable STATE it is bad input, unless --truth-only; --print-start gives the start.
  EXPECT_EQ(ts::run({ts::tool("hold"), "--log", truth_only}).exit_code, kExitBadInput);
  r = ts::run({ts::tool("hold"), "--log", log, "--print-start"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_EQ(r.out, "--init-position 1.000000,2.000000,3.000000 --init-yaw 0.500000\n");
}

}  // namespace
}  // namespace kestrel::estimator
