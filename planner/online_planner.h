#pragma once
// The planner behind the `kestrel-planner` process, free of LCM and clocks: it keeps the
// latest map (as a grid with wall features) and the latest state, and answers requests with
// BRM or PRM. Roadmaps are built per request from a seed derived from the request id, so the
// same inputs always give the same plan (lock-step replay). Start and goal must be in known
// free space, except that a request starting from the state takes the unknown cells within
// start_unknown_free_m of it as free: the vehicle is there, and its camera never sees the space
// around it (behind it, beside it, inside its minimum range).

#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "planner/grid_environment.h"
#include "planner/roadmap.h"
#include "planner/search.h"
#include "planner/sensor_model.h"

namespace kestrel::planner {

/// The paper's 100 samples, grown up to 1000 while start and goal are not connected.
inline RoadmapOptions grown_roadmap() {
  RoadmapOptions r;
  r.max_samples = 1000;
  return r;
}

struct OnlinePlannerOptions {
  SpaceOptions space;  ///< z_min_m / z_max_m: flight band for samples
  FeatureSensorOptions sensor = FeatureSensorOptions::kinect();
  MotionOptions motion;
  RoadmapOptions roadmap = grown_roadmap();
  double map_z_min_m = 0.3, map_z_max_m = 2.0;  ///< band of the map that matters for collisions
  double feature_density_per_m2 = 4.0;          ///< features assumed on the map's walls
  std::string sampler = "su";                   ///< uniform | su | gaussian | bridge
  /// Unknown cells within this of a start from STATE count as free (at least the vehicle's
  /// radius plus a cell): the vehicle fills part of that space and its camera cannot see the
  /// rest (behind and beside it, and nothing nearer than the Kinect's 0.5 m). An obstacle in
  /// that blind ring goes unnoticed: the price of being able to leave a hover at all.
  double start_unknown_free_m = 0.8;
};

struct PlanQuery {
  long request_id = 0;
  std::optional<Config> start;  ///< nullopt: the latest state
  double start_trace = 0.0;     ///< with `start`: tr(Sigma), spread evenly
  Config goal = Config::Zero();
  bool brm = true;
  BrmPruning pruning = BrmPruning::kTrace;  ///< BRM only
  double dominance_slack = kToolsDominanceSlack;  ///< kCovarianceDominance only (BrmQuery)
  BrmObjective objective = BrmObjective::kMinGoalUncertainty;
  double max_trace = std::numeric_limits<double>::infinity();
};

struct PlanAnswer {
  enum Status { kOk, kNoPath, kStartInCollision, kGoalInCollision, kNoMap, kBadRequest } status = kNoMap;
  std::string message;
  std::vector<Config> waypoints;
  std::vector<double> traces;  ///< predicted tr(Sigma) at each waypoint
  std::vector<Mat4> covariances;  ///< the predicted Sigma at each waypoint (traces are theirs)
  double length_m = 0.0;
};

class OnlinePlanner {
 public:
  explicit OnlinePlanner(OnlinePlannerOptions options);
  /// Replaces the map; features are placed on its walls (deterministic for the grid).
  void set_map(OccupancyGrid grid);
  /// The latest vehicle state: configuration and its 4 x 4 covariance.
  void set_state(const Config& q, const Mat4& covariance);
  PlanAnswer plan(const PlanQuery& query) const;
  void reset();
  bool has_map() const { return env_ != nullptr; }

 private:
  /// The map with the unknown cells the vehicle at q fills made free; null when there are none.
  std::unique_ptr<GridEnvironment> with_vehicle_space(const Config& q) const;

  OnlinePlannerOptions options_;
  std::unique_ptr<GridEnvironment> env_;
  std::optional<std::pair<Config, Mat4>> state_;
};

}  // namespace kestrel::planner
