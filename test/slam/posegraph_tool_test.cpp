// kestrel-posegraph as a user runs it: a graph in, the optimised graph out, the figures
// printed; a malformed file is exit code 3 with one line naming the file and line, and so are
// information matrices that are not positive semi-definite (unless --repair-information) and
// values that would overflow chi2; parts of the graph the anchor does not reach are anchored
// and named.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
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

// Exit 3, one line on stderr that starts with `expect`, no result on stdout.
void expect_refused(const std::string& text, const std::string& expect) {
  TempDir dir;
  std::ofstream(dir / "bad.g2o") << text;
  const auto r = run({tool("posegraph"), (dir / "bad.g2o").string(), "--out", (dir / "out.g2o").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << text << r.out << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-posegraph: error: " + (dir / "bad.g2o").string() + expect, 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out.find("chi2"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.g2o"));
}

TEST(PosegraphTool, InformationThatIsNotPositiveSemiDefiniteIsExitCode3UnlessRepaired) {
  const std::string text = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 1 5 0 1 0 1\n";
  expect_refused(text, ":3: edge 0 -> 1: information matrix is not positive semi-definite");
  expect_refused("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 -1 0 0 -1 0 -1\n",
                 ":3: edge 0 -> 1: information matrix has no positive eigenvalue");
  TempDir dir;
  std::ofstream(dir / "g.g2o") << text;
  const auto r = run({tool("posegraph"), (dir / "g.g2o").string(), "--repair-information"});
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.err.find("1 information matrices were not positive semi-definite and were replaced by the nearest "
                       "ones (--repair-information; the first on line 3)"),
            std::string::npos)
      << r.err;
}

TEST(PosegraphTool, NonFiniteAndAbsurdValuesAreExitCode3NeverANanChi2) {
  const std::string vertices = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  expect_refused(vertices + "EDGE_SE2 0 1 1e300 0 0 1 0 0 1 0 1\n", ":3: field 4 1e+300 is beyond 1e+09 in magnitude");
  expect_refused(vertices + "EDGE_SE2 0 1 1 0 0 1e300 0 0 1 0 1\n", ":3: field 7 1e+300 is beyond 1e+18 in magnitude");
  expect_refused(vertices + "EDGE_SE2 0 1 1 0 nan 1 0 0 1 0 1\n", ":3: field 6 is not finite");
  expect_refused("VERTEX_SE2 0 inf 0 0\n", ":1: field 3 is not finite");
  expect_refused("VERTEX_SE3:QUAT 0 0 0 -1e300 0 0 0 1\n", ":1: field 5 -1e+300 is beyond 1e+09 in magnitude");
  expect_refused("", ": no vertices or edges");
  expect_refused(vertices + "EDGE_SE2 0 1 1 0 0 1 0\n", ":3: EDGE_SE2 needs 11 values, found 7");
}

// A graph in two parts, the second not reaching the file's anchor (FIX 0): the tool holds it
// at its first vertex, says so, and reaches the optimum (chi2 0: the measurements are exact).
TEST(PosegraphTool, APartNotConnectedToTheAnchorIsAnchoredAndNamed) {
  TempDir dir;
  test::SyntheticOptions o;
  o.num_poses = 120;
  const auto truth = test::helix_graph(o);
  auto g = truth;
  g.edges.clear();
  for (const auto& e : truth.edges)
    if ((e.from < 60) == (e.to < 60)) g.edges.push_back(e);
  test::perturb(g, 0.3, 0.1, 5);
  write_g2o(dir / "in.g2o", g);
  const auto r = run({tool("posegraph"), (dir / "in.g2o").string(), "--out", (dir / "out.g2o").string()});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("anchored parts    1 not connected to the anchor, each held at its first vertex: vertex 60 "
                       "(60 vertices)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("60 vertices in 1 parts of the graph are not connected to the anchor (FIX 0)"),
            std::string::npos)
      << r.err;
  const auto given = std::get<PoseGraph3d>(read_g2o(dir / "in.g2o"));
  const auto out = std::get<PoseGraph3d>(read_g2o(dir / "out.g2o"));
  EXPECT_LT(chi2(out), 1e-9);
  EXPECT_EQ(out.fixed, given.fixed) << "the file's anchors, no more";
  for (const int v : {0, 60})  // held where the file put them (to the text's rounding)
    EXPECT_LT((out.poses[v].matrix() - given.poses[v].matrix()).cwiseAbs().maxCoeff(), 1e-12) << v;

  // A file of edges only gives no pose to place a second part by: refused, naming a vertex.
  expect_refused("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 5 6 1 0 0 1 0 0 1 0 1\n",
                 ": pose graph: vertex 5 is not connected to an anchored vertex");
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
