#include "test/slam/synthetic_graphs.h"

#include <cmath>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"

namespace kestrel::slam::test {
namespace {

Vector6d gaussian6(std::mt19937& rng, double t_sigma, double r_sigma) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d d;
  for (int k = 0; k < 3; ++k) d(k) = t_sigma * n(rng);
  for (int k = 3; k < 6; ++k) d(k) = r_sigma * n(rng);
  return d;
}

template <class Space>
void add_edge(PoseGraph<Space>& g, int i, int j, const typename Space::Pose& Z, double t_sigma,
              double r_sigma, EdgeKind kind) {
  typename Space::Matrix info = Space::Matrix::Identity();
  const double ts = std::max(t_sigma, 1e-3), rs = std::max(r_sigma, 1e-3);
  // g2o's rotation error is vec(q) ~ angle / 2: its standard deviation is half the angle's.
  for (int k = 0; k < Space::kDim - Space::kRotationDim; ++k) info(k, k) = 1.0 / (ts * ts);
  for (int k = Space::kDim - Space::kRotationDim; k < Space::kDim; ++k) {
    info(k, k) = Space::kRotationDim == 3 ? 4.0 / (rs * rs) : 1.0 / (rs * rs);
  }
  g.add_edge(i, j, Z, info, kind);
}

}  // namespace

PoseGraph3d helix_graph(const SyntheticOptions& o) {
  PoseGraph3d g;
  const double radius = 5.0, climb = 0.5;
  for (int k = 0; k < o.num_poses; ++k) {
    const double a = 2.0 * kPi * k / o.poses_per_turn;
    const Eigen::Vector3d p(radius * std::cos(a), radius * std::sin(a),
                            climb * k / o.poses_per_turn);
    // Facing along the path, with a wobble so that every axis of rotation is exercised.
    const Eigen::Matrix3d R = so3::exp(Eigen::Vector3d(0.1 * std::sin(3 * a), 0.1 * std::cos(2 * a),
                                                       a + kPi / 2));
    g.add_vertex(k, se3::make(R, p), k == 0);
  }
  std::mt19937 rng(o.seed);
  auto measure = [&](int i, int j, EdgeKind kind) {
    const Eigen::Isometry3d Z = g.poses[i].inverse() * g.poses[j];
    const Vector6d d = gaussian6(rng, o.translation_sigma, o.rotation_sigma);
    add_edge(g, i, j, se3::boxplus(Z, d), o.translation_sigma, o.rotation_sigma, kind);
  };
  for (int k = 0; k + 1 < o.num_poses; ++k) measure(k, k + 1, EdgeKind::kOdometry);
  for (int k = 0; k + o.poses_per_turn < o.num_poses; k += o.loop_stride) {
    measure(k + o.poses_per_turn, k, EdgeKind::kLoopClosure);
  }
  return g;
}

PoseGraph2d spiral_graph(const SyntheticOptions& o) {
  PoseGraph2d g;
  for (int k = 0; k < o.num_poses; ++k) {
    const double a = 2.0 * kPi * k / o.poses_per_turn;
    const double r = 5.0 + 0.2 * k / o.poses_per_turn;
    g.add_vertex(k, Se2::Pose(r * std::cos(a), r * std::sin(a), wrap_angle(a + kPi / 2)), k == 0);
  }
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> n(0.0, 1.0);
  auto measure = [&](int i, int j, EdgeKind kind) {
    Se2::Pose Z = Se2::compose(Se2::inverse(g.poses[i]), g.poses[j]);
    Z += Se2::Pose(o.translation_sigma * n(rng), o.translation_sigma * n(rng), o.rotation_sigma * n(rng));
    Z.z() = wrap_angle(Z.z());
    add_edge(g, i, j, Z, o.translation_sigma, o.rotation_sigma, kind);
  };
  for (int k = 0; k + 1 < o.num_poses; ++k) measure(k, k + 1, EdgeKind::kOdometry);
  for (int k = 0; k + o.poses_per_turn < o.num_poses; k += o.loop_stride) {
    measure(k + o.poses_per_turn, k, EdgeKind::kLoopClosure);
  }
  return g;
}

void perturb(PoseGraph3d& graph, double translation_m, double rotation_rad, unsigned seed) {
  std::mt19937 rng(seed);
  for (int v = 0; v < graph.num_vertices(); ++v) {
    if (graph.fixed[v]) continue;
    graph.poses[v] = se3::boxplus(graph.poses[v], gaussian6(rng, translation_m, rotation_rad));
  }
}

void perturb(PoseGraph2d& graph, double translation_m, double rotation_rad, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int v = 0; v < graph.num_vertices(); ++v) {
    if (graph.fixed[v]) continue;
    auto& p = graph.poses[v];
    p += Se2::Pose(translation_m * n(rng), translation_m * n(rng), rotation_rad * n(rng));
    p.z() = wrap_angle(p.z());
  }
}

double max_translation_error(const PoseGraph3d& a, const PoseGraph3d& b) {
  double m = 0.0;
  for (int v = 0; v < a.num_vertices(); ++v) {
    m = std::max(m, (a.poses[v].translation() - b.poses[v].translation()).norm());
  }
  return m;
}

double max_rotation_error(const PoseGraph3d& a, const PoseGraph3d& b) {
  double m = 0.0;
  for (int v = 0; v < a.num_vertices(); ++v) m = std::max(m, se3::rotation_distance(a.poses[v], b.poses[v]));
  return m;
}

double max_translation_error(const PoseGraph2d& a, const PoseGraph2d& b) {
  double m = 0.0;
  for (int v = 0; v < a.num_vertices(); ++v) {
    m = std::max(m, (a.poses[v].head<2>() - b.poses[v].head<2>()).norm());
  }
  return m;
}

double max_rotation_error(const PoseGraph2d& a, const PoseGraph2d& b) {
  double m = 0.0;
  for (int v = 0; v < a.num_vertices(); ++v) {
    m = std::max(m, std::abs(wrap_angle(a.poses[v].z() - b.poses[v].z())));
  }
  return m;
}

}  // namespace kestrel::slam::test
