#pragma once
// The one harness every planner and sampler runs through (as OMPL's benchmark tool): a
// scenario (environment, vehicle, sensor, motion, roadmap options) and a setting (planner,
// sampler, sample count) give a trial: roadmap build, search, and the plan flown through
// step-by-step EKF propagation. Evaluation code, so it may read the clock (build and search
// times); the planning library itself never does.

#include <memory>
#include <string>
#include <vector>

#include "planner/search.h"
#include "planner/sensor_model.h"

namespace kestrel::planner::eval {

struct Scenario {
  const Environment* env = nullptr;
  SpaceOptions space;
  FeatureSensorOptions sensor = FeatureSensorOptions::paper_camera();
  MotionOptions motion;
  RoadmapOptions roadmap = RoadmapOptions::all_pairs();  ///< the paper's rule: every collision-free pair
  Mat4 start_covariance = 0.1 * Mat4::Identity();
  double max_trace = 100.0;  ///< success: a path whose nodes all stay below this tr(Sigma)
  Mat4 ukf_prior = 0.1 * Mat4::Identity();  ///< the constant prior of the UKF information gain
};

struct Setting {
  std::string planner = "brm";   ///< brm (Algorithm 1) | brm-dominance (BrmPruning::kCovarianceDominance) | prm
  std::string sampler = "su";    ///< uniform | su (EKF tr(M)) | su-ukf (I(x)) | gaussian | bridge
  int samples = 100;
  /// brm-dominance's BrmQuery::dominance_slack: 0 is exact up to the no-revisit rule but can
  /// take minutes on a grown 3000-sample roadmap; 1 % costs ~1 % and ~45x less time.
  double dominance_slack = kToolsDominanceSlack;
  /// > 0: BRM's other objective, the shortest path whose tr(Sigma) stays below this at every
  /// node (the paper's first one, §4; what a vehicle that must stay localised flies); 0: the
  /// least uncertain goal (Algorithm 1 as the tables run it).
  double max_trace = 0.0;
};

struct Trial {
  bool found = false;
  bool success = false;
  double goal_trace = 0.0;   ///< flown (step-by-step EKF) tr(Sigma) at the goal
  double max_trace = 0.0;    ///< largest flown tr(Sigma) along the path
  double length_m = 0.0;
  double build_s = 0.0;      ///< sampling + edges (+ transfers for BRM)
  double search_s = 0.0;
  std::vector<Config> path;
  std::vector<Config> samples;
};

Trial run_trial(const Scenario& scenario, const Setting& setting, const Config& start, const Config& goal,
                uint64_t seed);

/// Flies `path` with `sensor`: step-by-step EKF from `start_covariance`; returns tr(Sigma) at
/// each step's end (the first entry is the start).
std::vector<double> fly(const std::vector<Config>& path, const BeliefModel& model, const Mat4& start_covariance);

/// The same flight's covariance at each node of `path` (the first is `start_covariance`).
std::vector<Mat4> node_covariances(const std::vector<Config>& path, const BeliefModel& model,
                                   const Mat4& start_covariance);

double path_length(const std::vector<Config>& path);

}  // namespace kestrel::planner::eval
