// The estimator's tools as a user runs them: kestrel-estimate and kestrel-fit-vo-noise on
// synthesised logs, their usage errors and exit codes, and kestrel-estimator's --help.

#include <gtest/gtest.h>

#include "common/error.h"
#include "common/trajectory.h"
#include "common/transport/log_file.h"
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

}  // namespace
}  // namespace kestrel::estimator
