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
  // A negative definite matrix, of which nothing would be left, is refused even so: the row
  // InformationNegativeDefiniteEvenWhenRepairing of bad_files().
}

// Values that parse but are absurd: squared, times the information, they overflowed chi2. The
// bounds themselves are admitted (real graphs reach them); beyond them is an error, the rows
// *BeyondBound of bad_files().
TEST(G2o, TheValueBoundsAdmitRealGraphs) {
  std::istringstream at_bounds("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1e9 -1e9 0 1e18 0 0 1e18 0 1\n");
  EXPECT_NO_THROW(parse_g2o(at_bounds, "t.g2o"));
}

// One malformed file per row, read as "bad.g2o": the error starts with the file and, when one
// line is to blame, that line ("bad.g2o:3: "; else "bad.g2o: "), and goes on to say what is
// wrong. The row's name is the test's (G2o/G2oErrors.NameTheFileAndLine/<name>).
struct BadG2o {
  const char* name;
  std::string text;
  int line;             // the line the error names; 0: the file as a whole
  const char* message;  // part of the error after its "bad.g2o:<line>: "
  bool repair = false;  // read with G2oReadOptions::project_information
};

void PrintTo(const BadG2o& bad, std::ostream* os) { *os << bad.name << ": \"" << bad.text << "\""; }

std::vector<BadG2o> bad_files() {
  const std::string two = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n";  // what most edge rows stand on
  return {
      {"UnknownRecord", "VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\n", 2, "unknown record 'VERTEX_XY'"},
      {"VertexTooFewValues", "VERTEX_SE2 0 0 0\n", 1, "needs 4 values, found 3"},
      {"VertexTooManyValues", "VERTEX_SE2 0 0 0 0 7\n", 1, "needs 4 values, found 5"},
      {"NotANumber", "VERTEX_SE2 0 0 zero 0\n", 1, "field 4 'zero' is not a number"},
      {"NaN", "VERTEX_SE2 0 0 nan 0\n", 1, "field 4 is not finite"},
      {"FractionalId", "VERTEX_SE2 0.5 0 0 0\n", 1, "is not an integer id"},
      {"VertexDefinedTwice", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n", 2, "vertex 0 already defined on line 1"},
      {"QuaternionNotUnit", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 2\n", 1, "quaternion of norm 2"},
      {"Se2AndSe3Mixed", "VERTEX_SE2 0 0 0 0\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n", 2, "mixes SE2 and SE3"},
      {"EdgeToItself", "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 0 1 0 0 1 0 0 1 0 1\n", 2, "joins vertex 0 to itself"},
      {"EdgeToUndefinedVertex", two + "EDGE_SE2 0 2 1 0 0 1 0 0 1 0 1\n", 3,
       "refers to vertex 2, which the file does not define"},
      {"EdgeTooFewValues", "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\n", 2, "needs 11 values, found 10"},
      {"FixOfUndefinedVertex", "VERTEX_SE2 0 0 0 0\nFIX 3\n", 2, "FIX of vertex 3"},
      {"EdgesOnlyDisconnected", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n", 0,
       "is not connected"},
      {"OnlyComments", "# nothing\n\n", 0, "no vertices or edges"},
      {"Empty", "", 0, "no vertices or edges"},
      // Non-finite and absurd values, wherever they stand.
      {"Infinite", "VERTEX_SE2 0 0 inf 0\n", 1, "field 4 is not finite"},
      {"MinusInfinite", "VERTEX_SE2 0 -inf 0 0\n", 1, "field 3 is not finite"},
      {"Se2CoordinateBeyondBound", "VERTEX_SE2 0 1e300 0 0\n", 1, "field 3 1e+300 is beyond 1e+09 in magnitude"},
      {"Se2AngleBeyondBound", "VERTEX_SE2 0 0 0 -1e300\n", 1, "field 5 -1e+300 is beyond 1e+09"},
      {"Overflowing", "VERTEX_SE2 0 0 0 1e400\n", 1, "field 5"},
      {"Se3CoordinateBeyondBound", "VERTEX_SE3:QUAT 0 0 0 1e300 0 0 0 1\n", 1, "field 5 1e+300 is beyond"},
      {"QuaternionNaN", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 nan\n", 1, "field 9 is not finite"},
      {"EdgeMeasurementBeyondBound", two + "EDGE_SE2 0 1 1e300 0 0 1 0 0 1 0 1\n", 3, "field 4 1e+300 is beyond 1e+09"},
      {"EdgeMeasurementJustBeyondBound", two + "EDGE_SE2 0 1 1.000001e9 0 0 1 0 0 1 0 1\n",
       3, "field 4 1e+09 is beyond 1e+09 in magnitude"},
      {"InformationBeyondBound", two + "EDGE_SE2 0 1 1 0 0 1e300 0 0 1 0 1\n", 3, "field 7 1e+300 is beyond 1e+18"},
      {"InformationJustBeyondBound", two + "EDGE_SE2 0 1 1 0 0 1.1e18 0 0 1 0 1\n", 3,
       "field 7 1.1e+18 is beyond 1e+18 in magnitude"},
      {"InformationNaN", two + "EDGE_SE2 0 1 1 0 0 nan 0 0 1 0 1\n", 3, "field 7 is not finite"},
      {"InformationInfinite", two + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 inf\n", 3, "field 12 is not finite"},
      {"Se3EdgeMeasurementBeyondBound",
       "EDGE_SE3:QUAT 0 1 1e300 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", 1,
       "field 4 1e+300 is beyond"},
      // Information that is not positive semi-definite, zero or negative.
      {"InformationZero", two + "EDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n", 3,
       "edge 0 -> 1: information matrix has no positive eigenvalue"},
      {"InformationNegativeDefinite", two + "EDGE_SE2 0 1 1 0 0 -1 0 0 -1 0 -1\n", 3,
       "edge 0 -> 1: information matrix has no positive eigenvalue"},
      {"InformationNegativeDefiniteEvenWhenRepairing", two + "EDGE_SE2 0 1 1 0 0 -1 0 0 -1 0 -1\n",
       3, "edge 0 -> 1: information matrix has no positive eigenvalue", true},
      {"InformationIndefinite",  // [[1 5][5 1]] has eigenvalue -4
       two + "EDGE_SE2 0 1 1 0 0 1 5 0 1 0 1\n", 3,
       "edge 0 -> 1: information matrix is not positive semi-definite (eigenvalue -4, largest 6)"},
      {"InformationNegativeDiagonal", two + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 -0.5\n", 3,
       "edge 0 -> 1: information matrix is not positive semi-definite (eigenvalue -0.5, largest 1)"},
      {"Se3InformationIndefinite",
       "EDGE_SE3:QUAT 4 5 1 0 0 0 0 0 1 -2 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", 1,
       "edge 4 -> 5: information matrix is not positive semi-definite (eigenvalue -2, largest 1)"},
      // Lines cut short, in the middle of a record or of a number.
      {"Se3VertexCutShort", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0\n", 1, "needs 8 values, found 7"},
      {"NumberCutShort", "VERTEX_SE2 0 0 0 1e\n", 1, "field 5 '1e' is not a number"},
      {"EdgeCutShort", two + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 0 1 1 0\n", 4, "needs 11 values, found 4"},
      {"FixWithoutId", "VERTEX_SE2 0 0 0 0\nFIX\n", 2, "FIX needs 1 values, found 0"},
  };
}

class G2oErrors : public ::testing::TestWithParam<BadG2o> {};

TEST_P(G2oErrors, NameTheFileAndLine) {
  const BadG2o& bad = GetParam();
  std::istringstream text(bad.text);
  G2oReadOptions options;
  options.project_information = bad.repair;
  try {
    parse_g2o(text, "bad.g2o", nullptr, options);
    FAIL() << "no error for:\n" << bad.text;
  } catch (const InputError& e) {
    const std::string what = e.what();
    const std::string where = bad.line > 0 ? "bad.g2o:" + std::to_string(bad.line) + ": " : "bad.g2o: ";
    EXPECT_EQ(what.rfind(where, 0), 0u) << what;
    EXPECT_NE(what.find(bad.message, where.size()), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(G2o, G2oErrors, ::testing::ValuesIn(bad_files()),
                         [](const ::testing::TestParamInfo<BadG2o>& row) { return std::string(row.param.name); });

TEST(G2o, AMissingFileIsAnInputError) {
  EXPECT_THROW(read_g2o("/nonexistent/graph.g2o"), InputError);
  ::kestrel::test::TempDir dir;
  EXPECT_THROW(write_g2o((dir / "no/such/dir/g.g2o").string(), PoseGraph2d{}), InputError);
}

}  // namespace
}  // namespace kestrel::slam
