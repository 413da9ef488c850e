// The pose-graph optimiser on the real and standard benchmark graphs of ../shared/data beside
// Ceres's Levenberg-Marquardt run from the same start: a final chi2 no worse (the smaller
// graphs here; the benchmark runs all twelve). Skips when the data is absent.

#include <gtest/gtest.h>

#include <filesystem>
#include <variant>

#include "slam/posegraph/g2o_io.h"
#include "slam/posegraph/optimizer.h"
#include "test/slam/ceres_posegraph.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

class PoseGraphData : public ::testing::TestWithParam<const char*> {};

TEST_P(PoseGraphData, FinalChi2IsNoWorseThanCeres) {
  const auto root = ::kestrel::test::shared_data();
  if (root.empty()) KESTREL_SKIP_ENVIRONMENT() << "../shared/data is absent: this test needs the g2o benchmarks";
  const auto path = root / "posegraph" / (std::string(GetParam()) + ".g2o");
  if (!std::filesystem::exists(path)) KESTREL_SKIP_ENVIRONMENT() << path << " is absent";
  const AnyPoseGraph graph = read_g2o(path);
  std::visit(
      [&](const auto& original) {
        auto ours = original;
        auto theirs = original;
        const OptimizerSummary s = optimize(ours);
        const test::CeresResult c = test::ceres_optimize(theirs);
        EXPECT_LE(s.final_chi2, c.final_chi2) << GetParam();
        EXPECT_LT(s.final_chi2, s.initial_chi2);
        // The anchor stays where the file put it.
        EXPECT_EQ(ours.poses[0].matrix(), original.poses[0].matrix());
        RecordProperty("kestrel_chi2", std::to_string(s.final_chi2));
        RecordProperty("ceres_chi2", std::to_string(c.final_chi2));
      },
      graph);
}

INSTANTIATE_TEST_SUITE_P(Small, PoseGraphData,
                         ::testing::Values("intel", "MIT", "CSAIL", "kitti_00", "smallGrid3D",
                                           "manhattan", "parking-garage"));

}  // namespace
}  // namespace kestrel::slam
