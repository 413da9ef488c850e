// kestrel-eval as a user runs it: options, exit codes, one-line errors, JSON, plot, logs.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/image/image_io.h"
#include "common/time.h"
#include "common/trajectory.h"
#include "test/eval/known_log.h"
#include "test/eval/synthetic.h"
#include "test/support/test_support.h"

namespace kestrel::eval {
namespace {

using kestrel::test::run;
using kestrel::test::RunResult;
using kestrel::test::TempDir;

RunResult eval(std::vector<std::string> args) {
  args.insert(args.begin(), kestrel::test::tool("eval").string());
  return run(args, 60.0);
}

size_t lines(const std::string& s) {
  return static_cast<size_t>(std::count(s.begin(), s.end(), '\n'));
}

// A ground truth and an estimate of the same helix, 90 frames, written as TUM files.
struct TumPair {
  TempDir dir;
  std::string gt = (dir / "gt.txt").string();
  std::string est = (dir / "est.txt").string();
  TumPair() {
    const auto times = test::frame_times(90);
    write_tum_trajectory(gt, test::helix(times));
    write_tum_trajectory(est, test::helix(times));
  }
};

TEST(EvalCli, HelpListsTheOptions) {
  const RunResult r = eval({"--help"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* option : {"--gt", "--est", "--frames", "--json", "--plot", "--to-tum",
                             "--no-align", "--rpe-delta", "--gross-velocity", "--config"})
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
}

TEST(EvalCli, BadArgumentsExit2) {
  const TumPair p;
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--gt", p.gt},                                       // no --est
           {"--est", p.est},                                     // no --gt and no --to-tum
           {"--gt", p.gt, "--est", p.est, "--rpe-delta", "-1"},  // not positive
           {"--gt", p.gt, "--est", p.est, "--bogus"},
           {"--gt", p.gt + ":GROUND_TRUTH", "--est", p.est},  // a channel of a text file
       }) {
    const RunResult r = eval(args);
    EXPECT_EQ(r.exit_code, 2) << args.back() << ": " << r.err;
    EXPECT_NE(r.err.find("kestrel-eval: error: "), std::string::npos) << r.err;
  }
}

TEST(EvalCli, MissingOrMalformedFileExits3WithOneLineNamingIt) {
  const TumPair p;
  const std::string missing = (p.dir / "missing.txt").string();
  RunResult r = eval({"--gt", missing, "--est", p.est});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-eval: error: " + missing + ": cannot open", 0), 0u) << r.err;

  std::ofstream(p.dir / "bad.txt") << "# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n";
  r = eval({"--gt", p.gt, "--est", (p.dir / "bad.txt").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find((p.dir / "bad.txt").string() + ":3: expected"), std::string::npos) << r.err;

  r = eval({"--gt", p.gt, "--est", p.est, "--frames", missing});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
}

TEST(EvalCli, NoOverlapExits1) {
  const TumPair p;
  std::vector<int64_t> later;
  for (int64_t t : test::frame_times(30)) later.push_back(t + 60000000);
  write_tum_trajectory(p.dir / "later.txt", test::helix(later));
  const RunResult r = eval({"--gt", p.gt, "--est", (p.dir / "later.txt").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no frame has both an estimate and ground truth"), std::string::npos)
      << r.err;
}

TEST(EvalCli, JsonParsesAndHoldsTheFigures) {
  const TumPair p;
  // A frame list with 10 more frames than the estimate: 10 gross failures of 100.
  std::ofstream list(p.dir / "rgb.txt");
  for (int64_t t : test::frame_times(100)) list << format_seconds(t) << " rgb/x.png\n";
  list.close();
  const RunResult r =
      eval({"--gt", p.gt, "--est", p.est, "--frames", (p.dir / "rgb.txt").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"]["count"], 100);
  EXPECT_EQ(j["frames"]["scored"], 90);
  EXPECT_EQ(j["frames"]["no_estimate"], 10);
  EXPECT_LT(j["ate_m"]["rmse"].get<double>(), 1e-6);  // TUM text keeps 9 digits
  EXPECT_EQ(j["gross_failures"]["total"], 10);
  EXPECT_DOUBLE_EQ(j["gross_failures"]["percent"].get<double>(), 10.0);
  EXPECT_EQ(j["rpe"]["delta_s"], 1.0);
}

// --world-from: a second run (frames 45..89) in the world of a first (0..44), whose estimate is
// the truth seen from another frame X: the first run's whole poses give X once, and the second,
// in X too, scores 0 with no alignment of its own; without it, not aligned, it is X's offset.
TEST(EvalCli, WorldFromScoresASecondRunInTheFirstRunsWorld) {
  TempDir dir;
  const auto times = test::frame_times(90);
  const Eigen::Isometry3d X = Eigen::Translation3d(1.0, -2.0, 0.5) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  Trajectory gt0, est0, gt1, est1;
  for (size_t i = 0; i < times.size(); ++i) {
    const Eigen::Isometry3d T = test::helix_pose(times[i]);
    (i < 45 ? gt0 : gt1).push_back(times[i], T);
    (i < 45 ? est0 : est1).push_back(times[i], X.inverse() * T);
  }
  for (const auto& [name, t] : {std::pair<const char*, const Trajectory*>{"gt0", &gt0}, {"est0", &est0}, {"gt1", &gt1}, {"est1", &est1}})
    write_tum_trajectory((dir / name).string(), *t);
  const RunResult r = eval({"--gt", (dir / "gt1").string(), "--est", (dir / "est1").string(), "--world-from",
                            (dir / "gt0").string(), (dir / "est0").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["ate_m"]["aligned"].get<bool>());
  EXPECT_LT(j["ate_m"]["rmse"].get<double>(), 1e-6);
  const RunResult plain = eval({"--gt", (dir / "gt1").string(), "--est", (dir / "est1").string(), "--no-align", "--json"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_GT(nlohmann::json::parse(plain.out)["ate_m"]["rmse"].get<double>(), 0.5);
  // A first run the truth does not cover gives no world: exit 3 naming it.
  const RunResult none = eval({"--gt", (dir / "gt1").string(), "--est", (dir / "est1").string(), "--world-from",
                               (dir / "gt1").string(), (dir / "est0").string()});
  EXPECT_EQ(none.exit_code, 3) << none.err;
  EXPECT_NE(none.err.find("covers no pose"), std::string::npos) << none.err;
}

TEST(EvalCli, TextReportNamesWhatWasCompared) {
  const TumPair p;
  const RunResult r = eval({"--gt", p.gt, "--est", p.est, "--no-align"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* s : {"ground truth", "estimate", "compared", "ATE, not aligned (m)",
                        "RPE translation, 1 s (m/s)", "RPE rotation, 1 s (deg/s)",
                        "velocity error (m/s)", "step error (m)", "gross failures", "0 of 90 frames (0.00 %)"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST(EvalCli, LogInputExportAndPlot) {
  TempDir dir;
  const std::string log = (dir / "run.lcmlog").string();
  test::KnownLog().write(log, kestrel::ground_truth_t::FRAME_BODY);
  const std::string tum = (dir / "vo.txt").string(), png = (dir / "plot.png").string();
  const RunResult r =
      eval({"--gt", log, "--est", log + ":VO_UPDATE", "--to-tum", tum, "--plot", png, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["compared"], "camera poses (ground truth converted from body with T_body_camera)");
  EXPECT_EQ(j["gross_failures"]["no_estimate"], 1);
  EXPECT_LT(j["ate_m"]["max"].get<double>(), 1e-9);
  EXPECT_EQ(read_tum_trajectory(tum).size(), 59u);
  const cv::Mat image = image::read_image(png);
  EXPECT_EQ(image.cols, 1000);
  EXPECT_EQ(image.rows, 1390);

  // Export alone, without ground truth.
  const RunResult only = eval({"--est", log, "--to-tum", (dir / "only.txt").string()});
  EXPECT_EQ(only.exit_code, 0) << only.err;
  EXPECT_EQ(read_tum_trajectory(dir / "only.txt").size(), 59u);
}

TEST(EvalCli, DamagedLogIsReportedAndTheRestEvaluated) {
  TempDir dir;
  const std::string log = (dir / "run.lcmlog").string();
  test::KnownLog().write(log, kestrel::ground_truth_t::FRAME_CAMERA);
  std::filesystem::resize_file(log, std::filesystem::file_size(log) - 40);
  const RunResult r = eval({"--gt", log, "--est", log, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("run.lcmlog: damaged LCM log: truncated last event"), std::string::npos)
      << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NE(j["estimate"]["diagnostics"]["damage"].get<std::string>(), "");
  EXPECT_GT(j["frames"]["scored"].get<int>(), 50);
}

}  // namespace
}  // namespace kestrel::eval
