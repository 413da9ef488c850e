// Reading and writing g2o files: round trips, edges-only files, and one error naming the file
// and line for every kind of malformed input.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/numbers.h"
#include "slam/posegraph/g2o_io.h"
#include "test/slam/synthetic_graphs.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

template <class Graph>
void expect_same(const Graph& a, const Graph& b) {
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  ASSERT_EQ(a.num_edges(), b.num_edges());
  EXPECT_EQ(a.ids, b.ids);
  EXPECT_EQ(a.fixed, b.fixed);
  EXPECT_LT(test::max_translation_error(a, b), 1e-12);
  EXPECT_LT(test::max_rotation_error(a, b), 1e-12);
  for (int k = 0; k < a.num_edges(); ++k) {
    EXPECT_EQ(a.edges[k].from, b.edges[k].from);
    EXPECT_EQ(a.edges[k].to, b.edges[k].to);
    EXPECT_EQ(a.edges[k].kind, b.edges[k].kind);
    EXPECT_LT((a.edges[k].information - b.edges[k].information).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(G2o, Se3RoundTrip) {
  test::SyntheticOptions o;
  o.num_poses = 60;
  o.translation_sigma = 0.1;
  o.rotation_sigma = 0.05;
  auto g = test::helix_graph(o);
  g.edges[3].information(0, 4) = g.edges[3].information(4, 0) = 0.25;  // off-diagonal terms survive
  ::kestrel::test::TempDir dir;
  write_g2o(dir / "g.g2o", g);
  const AnyPoseGraph back = read_g2o(dir / "g.g2o");
  ASSERT_TRUE(std::holds_alternative<PoseGraph3d>(back));
  expect_same(std::get<PoseGraph3d>(back), g);
  // Measurements too.
  for (int k = 0; k < g.num_edges(); ++k) {
    const auto& a = g.edges[k].measurement;
    const auto& b = std::get<PoseGraph3d>(back).edges[k].measurement;
    EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(G2o, Se2RoundTrip) {
  test::SyntheticOptions o;
  o.num_poses = 60;
  o.translation_sigma = 0.1;
  o.rotation_sigma = 0.05;
  auto g = test::spiral_graph(o);
  for (auto& id : g.ids) id += 100;  // ids need not start at zero
  std::stringstream text;
  write_g2o(text, g);
  const AnyPoseGraph back = parse_g2o(text, "memory");
  ASSERT_TRUE(std::holds_alternative<PoseGraph2d>(back));
  expect_same(std::get<PoseGraph2d>(back), g);
}

TEST(G2o, ReadsVerticesEdgesAndFix) {
  std::istringstream text(
      "# a comment\n"
      "VERTEX_SE2 0 0 0 0\n"
      "VERTEX_SE2 1 1.0 0 1.5707963267948966\n"
      "\n"
      "VERTEX_SE2 2 1.0 1.0 3.141592653589793\n"
      "EDGE_SE2 0 1 1 0 1.5707963267948966 1 0 0 1 0 1\n"
      "EDGE_SE2 2 0 1 1 0 10 2 0 20 0 30\r\n"
      "FIX 1\n");
  const auto g = std::get<PoseGraph2d>(parse_g2o(text, "t.g2o"));
  ASSERT_EQ(g.num_vertices(), 3);
  ASSERT_EQ(g.num_edges(), 2);
  EXPECT_EQ(g.edges[0].kind, EdgeKind::kOdometry);
  EXPECT_EQ(g.edges[1].kind, EdgeKind::kLoopClosure);
  EXPECT_EQ(g.edges[1].from, 2);
  EXPECT_DOUBLE_EQ(g.edges[1].information(0, 1), 2.0);
  EXPECT_DOUBLE_EQ(g.edges[1].information(1, 0), 2.0);
  EXPECT_DOUBLE_EQ(g.edges[1].information(2, 2), 30.0);
  EXPECT_EQ(g.fixed, (std::vector<char>{0, 1, 0}));
  EXPECT_NEAR(g.poses[2].z(), kPi, 1e-15);
}

TEST(G2o, EdgesOnlyFilesAreInitialisedByChainingOdometry) {
  // A unit square walked counter-clockwise, ids not starting at zero, and a loop closure that
  // disagrees with the odometry: the chain follows the odometry.
  std::istringstream text(
      "EDGE_SE2 10 11 1 0 1.5707963267948966 1 0 0 1 0 1\n"
      "EDGE_SE2 11 12 1 0 1.5707963267948966 1 0 0 1 0 1\n"
      "EDGE_SE2 12 13 1 0 1.5707963267948966 1 0 0 1 0 1\n"
      "EDGE_SE2 13 10 5 0 0 1 0 0 1 0 1\n");
  const auto g = std::get<PoseGraph2d>(parse_g2o(text, "square.g2o"));
  ASSERT_EQ(g.num_vertices(), 4);
  EXPECT_EQ(g.ids, (std::vector<int64_t>{10, 11, 12, 13}));
  const Eigen::Vector3d expected[] = {{0, 0, 0}, {1, 0, kPi / 2}, {1, 1, kPi}, {0, 1, -kPi / 2}};
  for (int v = 0; v < 4; ++v) {
    EXPECT_LT((g.poses[v].head<2>() - expected[v].head<2>()).norm(), 1e-12) << v;
    EXPECT_NEAR(std::abs(wrap_angle(g.poses[v].z() - expected[v].z())), 0.0, 1e-12) << v;
  }
  EXPECT_EQ(g.edges[3].kind, EdgeKind::kLoopClosure);
}

TEST(G2o, InformationThatIsNotPositiveSemiDefiniteIsRejectedNamingTheLineAndEdge) {
  std::istringstream text(
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
      "EDGE_SE2 0 1 1 0 0 1 5 0 1 0 1\n");  // [[1 5][5 1]] has eigenvalue -4
  try {
    parse_g2o(text, "t.g2o");
    FAIL() << "a matrix with eigenvalue -4 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("t.g2o:3: edge 0 -> 1: information matrix is not positive "
                                          "semi-definite (eigenvalue -4, largest 6)", 0),
              0u)
        << e.what();
  }
}

TEST(G2o, InformationThatIsNotPositiveSemiDefiniteIsRepairedAndCountedWhenAsked) {
  std::istringstream text(
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
      "EDGE_SE2 0 1 1 0 0 1 5 0 1 0 1\n");  // [[1 5][5 1]] has eigenvalue -4
  G2oStats stats;
  G2oReadOptions repair;
  repair.project_information = true;
  const auto g = std::get<PoseGraph2d>(parse_g2o(text, "t.g2o", &stats, repair));
  EXPECT_EQ(stats.repaired_information, 1);
  EXPECT_EQ(stats.first_repaired_line, 3);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(g.edges[0].information);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12);
  EXPECT_NEAR(g.edges[0].information(0, 1), 3.0, 1e-12);  // (1+5)/2 on the kept eigenvector

  // Nothing would be left of a negative definite matrix: refused even so.
  std::istringstream negative("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 -1 0 0 -1 0 -1\n");
  try {
    parse_g2o(negative, "t.g2o", &stats, repair);
    FAIL() << "a negative definite matrix was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.g2o:3: edge 0 -> 1: information matrix has no positive eigenvalue"),
              std::string::npos)
        << e.what();
  }
}

// Values that parse but are absurd: squared, times the information, they overflowed chi2.
TEST(G2o, ValuesBeyondTheBoundsAreRejectedAndTheBoundsAdmitRealGraphs) {
  const std::string vertices = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  std::istringstream at_bounds(vertices + "EDGE_SE2 0 1 1e9 -1e9 0 1e18 0 0 1e18 0 1\n");
  EXPECT_NO_THROW(parse_g2o(at_bounds, "t.g2o"));
  std::istringstream beyond(vertices + "EDGE_SE2 0 1 1.000001e9 0 0 1 0 0 1 0 1\n");
  EXPECT_THROW(parse_g2o(beyond, "t.g2o"), InputError);
  std::istringstream information(vertices + "EDGE_SE2 0 1 1 0 0 1.1e18 0 0 1 0 1\n");
  EXPECT_THROW(parse_g2o(information, "t.g2o"), InputError);
}

struct Malformed {
  const char* text;
  int line;
  const char* message;  // part of the error
};

class G2oErrors : public ::testing::TestWithParam<Malformed> {};

TEST_P(G2oErrors, NameTheFileAndLine) {
  const Malformed& m = GetParam();
  std::istringstream text(m.text);
  try {
    parse_g2o(text, "bad.g2o");
    FAIL() << "no error for:\n" << m.text;
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (m.line > 0) {
      EXPECT_NE(what.find("bad.g2o:" + std::to_string(m.line) + ":"), std::string::npos) << what;
    }
    EXPECT_NE(what.find(m.message), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    G2o, G2oErrors,
    ::testing::Values(
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\n", 2, "unknown record 'VERTEX_XY'"},
        Malformed{"VERTEX_SE2 0 0 0\n", 1, "needs 4 values, found 3"},
        Malformed{"VERTEX_SE2 0 0 0 0 7\n", 1, "needs 4 values, found 5"},
        Malformed{"VERTEX_SE2 0 0 zero 0\n", 1, "field 4 'zero' is not a number"},
        Malformed{"VERTEX_SE2 0 0 nan 0\n", 1, "field 4 is not finite"},
        Malformed{"VERTEX_SE2 0.5 0 0 0\n", 1, "is not an integer id"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", 2, "vertex 0 already defined on line 1"},
        Malformed{"VERTEX_SE3:QUAT 0 0 0 0 0 0 0 2\n", 1, "quaternion of norm 2"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n", 2, "mixes SE2 and SE3"},
        Malformed{"VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n", 2, "joins vertex 0 to itself"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 2 1 0 0 1 0 0 1 0 1\n", 3,
                  "refers to vertex 2, which the file does not define"},
        Malformed{"VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\n", 2, "needs 11 values, found 10"},
        Malformed{"VERTEX_SE2 0 0 0 0\nFIX 3\n", 2, "FIX of vertex 3"},
        Malformed{"EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n", 0,
                  "is not connected"},
        Malformed{"# nothing\n\n", 0, "no vertices or edges"},
        Malformed{"", 0, "no vertices or edges"},
        // Non-finite and absurd values, wherever they stand.
        Malformed{"VERTEX_SE2 0 0 inf 0\n", 1, "field 4 is not finite"},
        Malformed{"VERTEX_SE2 0 -inf 0 0\n", 1, "field 3 is not finite"},
        Malformed{"VERTEX_SE2 0 1e300 0 0\n", 1, "field 3 1e+300 is beyond 1e+09 in magnitude"},
        Malformed{"VERTEX_SE2 0 0 0 -1e300\n", 1, "field 5 -1e+300 is beyond 1e+09"},
        Malformed{"VERTEX_SE2 0 0 0 1e400\n", 1, "field 5"},
        Malformed{"VERTEX_SE3:QUAT 0 0 0 1e300 0 0 0 1\n", 1, "field 5 1e+300 is beyond"},
        Malformed{"VERTEX_SE3:QUAT 0 0 0 0 0 0 0 nan\n", 1, "field 9 is not finite"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1e300 0 0 1 0 0 1 0 1\n", 3,
                  "field 4 1e+300 is beyond 1e+09"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1e300 0 0 1 0 1\n", 3,
                  "field 7 1e+300 is beyond 1e+18"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 nan 0 0 1 0 1\n", 3,
                  "field 7 is not finite"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 inf\n", 3,
                  "field 12 is not finite"},
        Malformed{"EDGE_SE3:QUAT 0 1 1e300 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", 1,
                  "field 4 1e+300 is beyond"},
        // Information that is not positive semi-definite, zero or negative.
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n", 3,
                  "edge 0 -> 1: information matrix has no positive eigenvalue"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 -1 0 0 -1 0 -1\n", 3,
                  "edge 0 -> 1: information matrix has no positive eigenvalue"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 -0.5\n", 3,
                  "edge 0 -> 1: information matrix is not positive semi-definite (eigenvalue -0.5, largest 1)"},
        Malformed{"EDGE_SE3:QUAT 4 5 1 0 0 0 0 0 1 -2 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", 1,
                  "edge 4 -> 5: information matrix is not positive semi-definite (eigenvalue -2, largest 1)"},
        // Lines cut short, in the middle of a record or of a number.
        Malformed{"VERTEX_SE3:QUAT 0 0 0 0 0 0 0\n", 1, "needs 8 values, found 7"},
        Malformed{"VERTEX_SE2 0 0 0 1e\n", 1, "field 5 '1e' is not a number"},
        Malformed{"VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 0 1 1 0\n", 4,
                  "needs 11 values, found 4"},
        Malformed{"VERTEX_SE2 0 0 0 0\nFIX\n", 2, "FIX needs 1 values, found 0"}));

TEST(G2o, AMissingFileIsAnInputError) {
  EXPECT_THROW(read_g2o("/nonexistent/graph.g2o"), InputError);
  ::kestrel::test::TempDir dir;
  EXPECT_THROW(write_g2o((dir / "no/such/dir/g.g2o").string(), PoseGraph2d{}), InputError);
}

}  // namespace
}  // namespace kestrel::slam
