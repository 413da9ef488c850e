#pragma once
// The roadmap shared by PRM and BRM: nodes (start, goal, samples), straight collision-free
// edges between nodes closer than a radius, and for BRM each directed edge's transfer
// function, computed once when the graph is built.
//
// An edge is the straight line in C = R^3 x S^1, flown as the follower (control/) flies a
// plan: the position moves linearly and the yaw turns from one node's yaw to the other's the
// shortest way round, so a node's sampled yaw is where its sensor looks. The line is cut
// into steps of at most `step_m` and `step_rad`; each step adds process noise
// R = V W V^T with W proportional to the distance flown (common/gaussian/information.h), G = I for
// the holonomic model, and gathers the sensor's information at the step's end.

#include <functional>
#include <limits>
#include <vector>

#include "planner/configuration_space.h"
#include "planner/sampler.h"
#include "planner/transfer.h"

namespace kestrel::planner {

struct MotionOptions {
  double step_m = 0.25;
  double step_rad = 0.25;  ///< yaw turned per step at most (under the paper camera's 30 deg field of view)
  /// Variance added per metre flown, per coordinate (x, y, z: m^2/m; yaw: rad^2/m).
  Eigen::Vector4d variance_per_m = Eigen::Vector4d(0.5, 0.5, 0.1, 0.05);
};

/// What an edge does to the belief: the motion model plus a sensor's information M(q).
class BeliefModel {
 public:
  BeliefModel(MotionOptions motion, std::function<Mat4(const Config&)> information)
      : motion_(std::move(motion)), information_(std::move(information)) {}
  /// Steps of the straight edge a -> b (empty if a == b).
  std::vector<BeliefStep> steps(const Config& a, const Config& b) const;
  const MotionOptions& motion() const { return motion_; }

 private:
  MotionOptions motion_;
  std::function<Mat4(const Config&)> information_;
};

struct Edge {
  int to = -1;
  double length_m = 0.0;
  ScatteringTransfer transfer;  ///< identity when built without a belief model
};

struct RoadmapOptions {
  int samples = 100;
  /// While start and goal are not connected, draw `samples` more (up to this many in all) and
  /// connect again; 0 or <= samples: a fixed count, as in the paper's experiments.
  int max_samples = 0;
  /// A practical limit for the tools' roadmaps, which grow to thousands of samples (all pairs
  /// of 3000 nodes would be 4.5 M collision checks); the paper has none (all_pairs()).
  double connect_radius_m = 6.0;
  int max_neighbours = 20;  ///< each node tries its nearest this many within the radius (0: all)

  /// The paper's Algorithm 1, step 2: every pair of nodes whose straight line is collision
  /// free is joined, whatever its length (no radius, no neighbour limit). The experiments'
  /// rule: with 100 samples a 6 m / 20-neighbour limit left the floor's corridor pair
  /// unconnected in 2 of 30 uniform roadmaps that all pairs connect.
  static RoadmapOptions all_pairs() {
    RoadmapOptions o;
    o.connect_radius_m = std::numeric_limits<double>::infinity();
    o.max_neighbours = 0;
    return o;
  }
};

class Roadmap {
 public:
  int add_node(const Config& q);
  /// Adds a -> b (and b -> a) with transfers from `model` when given.
  void connect(int a, int b, const BeliefModel* model);
  /// Adds a directed edge with an explicit transfer (hand-built graphs, tests).
  void add_edge(int from, int to, double length_m, const ScatteringTransfer& transfer);

  int size() const { return static_cast<int>(nodes_.size()); }
  const Config& node(int i) const { return nodes_[i]; }
  const std::vector<Edge>& edges(int i) const { return adjacency_[i]; }
  int edge_count() const;

 private:
  std::vector<Config> nodes_;
  std::vector<std::vector<Edge>> adjacency_;
};

/// The largest tr(Sigma) at the ends of the steps of the edge a -> b flown from `sigma`
/// (step-by-step EKF, as the experiments fly a plan): the edge's end included, its start
/// (a node, checked on its own) not; tr(sigma) for an edge of no steps.
double peak_trace_along(const BeliefModel& model, const Config& a, const Config& b, const Mat4& sigma);

/// Node 0 = start, node 1 = goal, then up to options.samples samples (more, up to
/// options.max_samples, while start and goal are not connected); each node is joined to its
/// nearest max_neighbours within the radius whose motion is valid (the union of both
/// directions' choices). A grown roadmap is the one built at once from all its samples, and
/// belief transfers are computed only for the final edges. `model` may be null (PRM).
Roadmap build_roadmap(const ConfigurationSpace& space, Sampler& sampler, const Config& start,
                      const Config& goal, const RoadmapOptions& options, const BeliefModel* model, Rng& rng);

}  // namespace kestrel::planner
