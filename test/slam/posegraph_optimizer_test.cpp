// The pose-graph optimiser against graphs with known answers, in the plane and in space: it
// recovers an exactly measured graph from a perturbed start, reaches the optimum of a noisy
// one from poor odometry, holds fixed vertices, anchors the parts the anchor does not reach,
// and a robust kernel defeats a false loop.

#include <gtest/gtest.h>

#include "slam/posegraph/chordal_init.h"
#include "slam/posegraph/optimizer.h"
#include "test/slam/synthetic_graphs.h"

namespace kestrel::slam {
namespace {

using test::SyntheticOptions;

PoseGraph3d make_graph(const SyntheticOptions& o, Se3*) { return test::helix_graph(o); }
PoseGraph2d make_graph(const SyntheticOptions& o, Se2*) { return test::spiral_graph(o); }

template <class Space>
PoseGraph<Space> graph(const SyntheticOptions& o) {
  return make_graph(o, static_cast<Space*>(nullptr));
}

bool same_pose(const Se2::Pose& a, const Se2::Pose& b) { return a == b; }
bool same_pose(const Se3::Pose& a, const Se3::Pose& b) { return a.matrix() == b.matrix(); }

template <class Space>
class OptimizerTest : public ::testing::Test {};
using Spaces = ::testing::Types<Se2, Se3>;
TYPED_TEST_SUITE(OptimizerTest, Spaces);

TYPED_TEST(OptimizerTest, RecoversAnExactGraphFromAPerturbedStart) {
  SyntheticOptions o;
  o.num_poses = 150;
  const auto truth = graph<TypeParam>(o);
  for (const bool chordal : {true, false}) {
    auto g = truth;
    test::perturb(g, 0.3, 0.1, 11);
    OptimizerOptions options;
    options.chordal_initialization = chordal;
    const OptimizerSummary s = optimize(g, options);
    EXPECT_GT(s.initial_chi2, 1e3);
    EXPECT_LT(s.final_chi2, 1e-12) << "chordal " << chordal;
    EXPECT_LT(test::max_translation_error(g, truth), 1e-7) << "chordal " << chordal;
    EXPECT_LT(test::max_rotation_error(g, truth), 1e-8) << "chordal " << chordal;
    EXPECT_EQ(s.used_chordal, chordal);
  }
}

TYPED_TEST(OptimizerTest, ChordalInitialisationIsExactOnAnExactGraph) {
  SyntheticOptions o;
  o.num_poses = 120;
  const auto truth = graph<TypeParam>(o);
  auto g = truth;
  test::perturb(g, 2.0, 0.8, 12);
  ASSERT_TRUE(chordal_initialize(g));
  EXPECT_LT(test::max_translation_error(g, truth), 1e-8);
  EXPECT_LT(test::max_rotation_error(g, truth), 1e-9);
}

TYPED_TEST(OptimizerTest, ReachesTheOptimumOfANoisyGraphFromOdometry) {
  SyntheticOptions o;
  o.num_poses = 240;
  o.translation_sigma = 0.05;
  o.rotation_sigma = 0.02;
  const auto truth = graph<TypeParam>(o);
  auto g = truth;
  test::chain_odometry(g);
  const double drift = test::max_translation_error(g, truth);
  const OptimizerSummary s = optimize(g);
  // At the optimum chi2 follows a chi-square law with (edges - free poses) * dim degrees of
  // freedom (mean = dof, sd = sqrt(2 dof)).
  const double dof = (g.num_edges() - (g.num_vertices() - 1)) * TypeParam::kDim;
  EXPECT_LT(s.final_chi2, dof + 5 * std::sqrt(2 * dof));
  EXPECT_GT(s.final_chi2, dof - 5 * std::sqrt(2 * dof));
  EXPECT_LT(s.final_chi2, s.initial_chi2);
  EXPECT_LT(test::max_translation_error(g, truth), 0.2 * drift);
  // A second run from the result cannot improve it: it was a minimum. (Its accepted steps
  // lower the cost; moving the result back onto the anchor is rigid, exact up to rounding.)
  auto again = g;
  OptimizerOptions warm;
  warm.chordal_initialization = false;
  const OptimizerSummary s2 = optimize(again, warm);
  EXPECT_LE(s2.final_chi2, s.final_chi2 * (1.0 + 1e-12)) << s2.final_chi2 - s.final_chi2;
  EXPECT_NEAR(s2.final_chi2, s.final_chi2, 1e-6 * s.final_chi2);
}

TYPED_TEST(OptimizerTest, FixedVerticesKeepTheirPosesExactly) {
  SyntheticOptions o;
  o.num_poses = 100;
  o.translation_sigma = 0.05;
  o.rotation_sigma = 0.02;
  auto g = graph<TypeParam>(o);
  g.fixed[0] = 0;
  g.fixed[40] = 1;
  g.fixed[77] = 1;
  const auto before = g;
  test::perturb(g, 0.5, 0.1, 13);
  g.poses[40] = before.poses[40];
  g.poses[77] = before.poses[77];
  optimize(g);
  for (const int v : {40, 77}) EXPECT_TRUE(same_pose(g.poses[v], before.poses[v])) << v;
}

TYPED_TEST(OptimizerTest, AGraphWithoutEdgesOrUnknownsIsLeftAlone) {
  PoseGraph<TypeParam> g;
  g.add_vertex(0, TypeParam::identity(), true);
  const OptimizerSummary s = optimize(g);
  EXPECT_EQ(s.stop, StopReason::kNothingToDo);
  EXPECT_EQ(s.iterations, 0);
}

TYPED_TEST(OptimizerTest, RejectsAnEdgeToAMissingVertex) {
  auto g = graph<TypeParam>(SyntheticOptions{});
  g.edges.back().to = g.num_vertices();
  EXPECT_THROW(optimize(g), std::invalid_argument);
  g.edges.back().to = g.edges.back().from;
  EXPECT_THROW(optimize(g), std::invalid_argument);
}

// The graph cut in two (no edge between poses below 75 and the rest) plus a vertex without
// edges: neither part after the cut reaches vertex 0, the anchor.
template <class Space>
PoseGraph<Space> cut_graph(const PoseGraph<Space>& truth) {
  PoseGraph<Space> g = truth;
  g.edges.clear();
  for (const auto& e : truth.edges)
    if ((e.from < 75) == (e.to < 75)) g.edges.push_back(e);
  g.add_vertex(999, truth.poses[20]);
  return g;
}

TYPED_TEST(OptimizerTest, FindsTheComponentsThatReachNoAnchor) {
  SyntheticOptions o;
  o.num_poses = 150;
  PoseGraph<TypeParam> g = cut_graph(graph<TypeParam>(o));
  std::vector<int> second(75);
  for (int i = 0; i < 75; ++i) second[i] = 75 + i;
  EXPECT_EQ(unanchored_components(g), (std::vector<std::vector<int>>{second, {150}}));
  g.fixed[0] = 0;  // none marked: vertex 0 is the anchor all the same
  EXPECT_EQ(unanchored_components(g).size(), 2u);
  g.fixed[0] = g.fixed[75] = g.fixed[150] = 1;  // each part anchored: nothing left over
  EXPECT_TRUE(unanchored_components(g).empty());
  EXPECT_TRUE(unanchored_components(graph<TypeParam>(o)).empty());
}

// Each part the anchor does not reach is held at its first vertex, so the solve reaches the
// optimum (chi2 0 on exact measurements), where an unanchored part's singular equations had
// stopped short; the caller learns which, and the graph's fixed flags are left as given.
TYPED_TEST(OptimizerTest, AnchorsEachDisconnectedPartAtItsFirstVertexAndReachesTheOptimum) {
  SyntheticOptions o;
  o.num_poses = 150;
  const auto truth = graph<TypeParam>(o);
  for (const bool chordal : {true, false}) {
    PoseGraph<TypeParam> g = cut_graph(truth);
    test::perturb(g, 0.3, 0.1, 17);
    const auto start = g;
    OptimizerOptions options;
    options.chordal_initialization = chordal;
    const OptimizerSummary s = optimize(g, options);
    ASSERT_EQ(s.anchored_components.size(), 2u) << "chordal " << chordal;
    EXPECT_EQ(s.anchored_components[0].vertex, 75);
    EXPECT_EQ(s.anchored_components[0].size, 75);
    EXPECT_EQ(s.anchored_components[1].vertex, 150);
    EXPECT_EQ(s.anchored_components[1].size, 1);
    EXPECT_GT(s.initial_chi2, 1e3);
    EXPECT_LT(s.final_chi2, 1e-12) << "chordal " << chordal;
    EXPECT_EQ(g.fixed, start.fixed) << "the flags are the caller's";
    for (const int v : {0, 75, 150}) EXPECT_TRUE(same_pose(g.poses[v], start.poses[v])) << v;
    // The anchored part's shape is the truth's: every pose relative to its first one.
    for (int v = 76; v < 150; ++v) {
      const auto rel = TypeParam::compose(TypeParam::inverse(g.poses[75]), g.poses[v]);
      const auto rel_truth = TypeParam::compose(TypeParam::inverse(truth.poses[75]), truth.poses[v]);
      EXPECT_LT(TypeParam::error(rel, rel_truth, TypeParam::identity()).norm(), 1e-6) << v;
    }
  }
  PoseGraph<TypeParam> connected = truth;
  test::perturb(connected, 0.3, 0.1, 17);
  EXPECT_TRUE(optimize(connected).anchored_components.empty());
}

// Noisy measurements from poor odometry: the result is the optimum of the same graph with the
// second part anchored by hand. (Unanchored, the chordal start on such a graph had stopped at
// about 19 times the optimum's chi2: kestrel-posegraph on a two-part spiral of 400 poses.)
TYPED_TEST(OptimizerTest, ADisconnectedNoisyGraphReachesTheOptimumOfItsAnchoredParts) {
  SyntheticOptions o;
  o.num_poses = 150;
  o.translation_sigma = 0.05;
  o.rotation_sigma = 0.02;
  PoseGraph<TypeParam> g = cut_graph(graph<TypeParam>(o));
  test::chain_odometry(g);  // each part along its own odometry
  test::perturb(g, 0.5, 0.2, 19);
  PoseGraph<TypeParam> by_hand = g;
  by_hand.fixed[75] = by_hand.fixed[150] = 1;
  const OptimizerSummary s = optimize(g);
  const OptimizerSummary reference = optimize(by_hand);
  ASSERT_TRUE(reference.anchored_components.empty());
  EXPECT_EQ(s.anchored_components.size(), 2u);
  EXPECT_NEAR(s.final_chi2, reference.final_chi2, 1e-6 * reference.final_chi2);
  EXPECT_LT(s.final_chi2, 0.1 * s.initial_chi2);
}

// A false loop closure: pose 50 is said to be where pose 30 is, though they are half a turn
// and ten metres apart. Least squares bends the whole trajectory to please it; a
// robust kernel lets it go.
template <class Space>
void add_false_loop(PoseGraph<Space>& g) {
  typename Space::Matrix info = g.edges.back().information;
  g.add_edge(30, 50, Space::identity(), info, EdgeKind::kLoopClosure);
}

TYPED_TEST(OptimizerTest, ARobustKernelDownweightsAFalseLoopClosure) {
  SyntheticOptions o;
  o.num_poses = 200;
  o.loop_stride = 10;
  o.translation_sigma = 0.03;
  o.rotation_sigma = 0.01;
  const auto truth = graph<TypeParam>(o);

  auto plain = truth;
  add_false_loop(plain);
  test::chain_odometry(plain);
  optimize(plain);
  const double plain_error = test::max_translation_error(plain, truth);
  EXPECT_GT(plain_error, 1.0) << "the false loop should distort a least-squares solution";

  for (const KernelType kernel : {KernelType::kCauchy, KernelType::kDcs}) {
    auto robust = truth;
    add_false_loop(robust);
    test::chain_odometry(robust);
    OptimizerOptions options;
    options.kernel = RobustKernel{kernel, 5.0};
    const OptimizerSummary s = optimize(robust, options);
    EXPECT_EQ(s.downweighted_edges, 1) << kernel_type_name(kernel);
    EXPECT_LT(test::max_translation_error(robust, truth), 0.3) << kernel_type_name(kernel);
  }
}

TEST(RobustKernel, CostsAndWeightsAreConsistent) {
  for (const KernelType type : {KernelType::kNone, KernelType::kHuber, KernelType::kCauchy, KernelType::kDcs}) {
    const RobustKernel k{type, 2.0};
    EXPECT_DOUBLE_EQ(k.cost(0.0), 0.0);
    EXPECT_DOUBLE_EQ(k.weight(0.0), 1.0);
    for (const double s : {0.5, 3.9, 4.1, 10.0, 100.0}) {
      const double h = 1e-6 * s;
      EXPECT_NEAR((k.cost(s + h) - k.cost(s - h)) / (2 * h), k.weight(s), 1e-6) << kernel_type_name(type) << " s=" << s;
      EXPECT_LE(k.cost(s), s + 1e-12);
    }
  }
  EXPECT_LT(RobustKernel({KernelType::kDcs, 2.0}).cost(1e9), 3 * 4.0 + 1e-9);  // bounded
  EXPECT_EQ(parse_kernel_type("cauchy"), KernelType::kCauchy);
  EXPECT_THROW(parse_kernel_type("tukey"), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::slam
