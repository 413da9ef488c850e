#pragma once
// Pose graphs with known answers for the tests and benchmarks: a trajectory (a helix in
// space, a spiral in the plane) whose odometry edges join consecutive poses and whose loop
// closures join poses that come back near each other, measured exactly or with Gaussian noise.

#include <random>

#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam::test {

struct SyntheticOptions {
  int num_poses = 200;
  int poses_per_turn = 40;    ///< loop closures join pose k to k + poses_per_turn
  int loop_stride = 1;        ///< every stride-th pose gets a loop closure
  double translation_sigma = 0.0;  ///< measurement noise (metres)
  double rotation_sigma = 0.0;     ///< measurement noise (radians)
  unsigned seed = 1;
};

/// The true poses (graph.poses) and the measurements; vertex 0 is fixed.
PoseGraph3d helix_graph(const SyntheticOptions& options);
PoseGraph2d spiral_graph(const SyntheticOptions& options);

/// Each free pose moved by a random step of the given size.
void perturb(PoseGraph3d& graph, double translation_m, double rotation_rad, unsigned seed);
void perturb(PoseGraph2d& graph, double translation_m, double rotation_rad, unsigned seed);

/// Odometry chained from vertex 0: what a robot believes without loop closures.
template <class Space>
void chain_odometry(PoseGraph<Space>& graph) {
  for (auto& e : graph.edges) {
    if (e.kind == EdgeKind::kOdometry && e.to == e.from + 1) {
      graph.poses[e.to] = Space::compose(graph.poses[e.from], e.measurement);
    }
  }
}

/// Largest translation and rotation difference between the poses of two graphs.
double max_translation_error(const PoseGraph3d& a, const PoseGraph3d& b);
double max_rotation_error(const PoseGraph3d& a, const PoseGraph3d& b);
double max_translation_error(const PoseGraph2d& a, const PoseGraph2d& b);
double max_rotation_error(const PoseGraph2d& a, const PoseGraph2d& b);

}  // namespace kestrel::slam::test
