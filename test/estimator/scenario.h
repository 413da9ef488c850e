#pragma once
// A complete estimator run on an analytic motion: a noisy IMU at 200 Hz and the synthetic VO
// at 30 Hz, delivered the way the processes deliver them (each VO update arrives a latency
// after its frame, between IMU samples), with the truth alongside for checking.

#include <functional>
#include <vector>

#include "estimator/estimator.h"
#include "estimator/eval/synthetic_vo.h"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator::test {

struct ScenarioOptions {
  double duration_s = 10.0;
  double imu_rate_hz = 200.0;
  double vo_rate_hz = 30.0;
  double vo_latency_s = 0.03;
  uint64_t seed = 1;
  ImuNoiseTruth imu;
  SyntheticVoOptions vo;
  bool start_from_truth = true;  ///< initialise with the true state and the init sigmas
  /// Applied to each VO update before delivery (e.g. to fail a stretch of frames).
  std::function<void(VoUpdate&)> alter_vo;
  /// IMU samples for which this returns true are not delivered (a gap).
  std::function<bool(const ImuSample&)> drop_imu;
};

struct ScenarioStep {
  EstimatorOutput output;
  NavState truth;  ///< with the true biases
};

/// Feeds everything to `estimator`; `before_imu(i)` (optional) runs before IMU sample i is
/// handed over, to inject extra inputs. Returns the output after every IMU sample.
std::vector<ScenarioStep> run_scenario(Estimator& estimator, const AnalyticMotion& motion,
                                       const ScenarioOptions& options,
                                       const std::function<void(size_t)>& before_imu = {});

/// The default scenario for `duration_s` with a small constant gyro bias: the run the gate and
/// robustness tests disturb, one for all of them so that a refused input is judged against the
/// same undisturbed run (the filter holds a bias estimate while inputs are refused around it).
ScenarioOptions gentle_run(double duration_s);

/// The initial covariance initialize() gets when starting from the truth.
Matrix15d initial_covariance(const InitOptions& init);

}  // namespace kestrel::estimator::test
