// kestrel-posegraph as a user runs it: a graph in, the optimised graph out, the figures
// printed; a malformed file is exit code 3 with one line naming the file and line.

#include <gtest/gtest.h>

#include <fstream>
#include <variant>

#include "common/error.h"
#include "slam/posegraph/g2o_io.h"
#include "test/slam/synthetic_graphs.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

using ::kestrel::test::run;
using ::kestrel::test::TempDir;
using ::kestrel::test::tool;

TEST(PosegraphTool, OptimisesAFileAndWritesTheResult) {
  TempDir dir;
  test::SyntheticOptions o;
  o.num_poses = 120;
  o.translation_sigma = 0.05;
  o.rotation_sigma = 0.02;
  auto g = test::helix_graph(o);
  const auto truth = g;
  test::chain_odometry(g);
  write_g2o(dir / "in.g2o", g);
  const auto r = run({tool("posegraph"), (dir / "in.g2o").string(), "--out", (dir / "out.g2o").string()});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("space             SE3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("vertices          120"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("final chi2"), std::string::npos) << r.out;
  const auto out = std::get<PoseGraph3d>(read_g2o(dir / "out.g2o"));
  EXPECT_LT(chi2(out), 0.01 * chi2(g));
  EXPECT_LT(test::max_translation_error(out, truth), 0.5);
}

TEST(PosegraphTool, AMalformedFileIsExitCode3NamingTheLine) {
  TempDir dir;
  std::ofstream(dir / "bad.g2o") << "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\n";
  const auto r = run({tool("posegraph"), (dir / "bad.g2o").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("bad.g2o:2: EDGE_SE2 needs 11 values, found 10"), std::string::npos) << r.err;
  const auto missing = run({tool("posegraph"), (dir / "none.g2o").string()});
  EXPECT_EQ(missing.exit_code, kExitBadInput);
  EXPECT_NE(missing.err.find("none.g2o: cannot open"), std::string::npos) << missing.err;
}

TEST(PosegraphTool, BadOptionsAreExitCode2) {
  TempDir dir;
  EXPECT_EQ(run({tool("posegraph"), "x.g2o", "--kernel", "tukey"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("posegraph"), "x.g2o", "--kernel-width", "-1"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("posegraph")}).exit_code, kExitUsage);
  const auto help = run({tool("posegraph"), "--help"});
  EXPECT_EQ(help.exit_code, kExitOk);
  EXPECT_NE(help.out.find("--kernel"), std::string::npos);
}

}  // namespace
}  // namespace kestrel::slam
