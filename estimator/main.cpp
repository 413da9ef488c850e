// kestrel-estimator: the onboard state estimator process. IMU, VO_UPDATE and SLAM_CORRECTION
// in; STATE out after every IMU sample once the filter has a state, or after every VO update
// without a gyro (state_estimator.h, README.md). A thin
// adapter: decode -> estimator library -> encode; lock-step replay resets it through Node.

#include <spdlog/spdlog.h>

#include <iostream>
#include <optional>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "estimator/cli_options.h"
#include "estimator/state_estimator.h"
#include "estimator/messages.h"

namespace {

using namespace kestrel;
using namespace kestrel::estimator;

struct Options {
  std::string lcm_url;
  EstimatorOptions estimator;
};

// Health follows the estimator: RUNNING while VO is being fused, DEGRADED without it (the IMU
// filter on the IMU alone, the visual-only one predicting), or on an IMU the mode cannot use.
// A refused input is rethrown to the Node, which counts it and shows DEGRADED with its reason
// (common/transport/node.h), as for every process.
void report_health(transport::Node& node, const StateEstimator& estimator) {
  const auto out = estimator.output();
  const bool visual = estimator.mode() == EstimatorMode::kVisualOnly;
  if (estimator.mode() == EstimatorMode::kImu && !out && estimator.incomplete_imu() > 0) {
    node.set_health(kestrel::process_status_t::STATE_DEGRADED,
                    "IMU samples lack the gyro or the accelerometer: --mode imu needs both "
                    "(--mode auto runs on the visual odometry without a gyro)");
  } else if (!out && estimator.settling()) {
    node.set_health(kestrel::process_status_t::STATE_STARTING,
                    "started on the move: waiting for the VO to measure velocity and tilt");
  } else if (!out) {
    node.set_health(kestrel::process_status_t::STATE_STARTING,
                    visual ? "visual only (no gyro): waiting for the first VO update"
                           : "initialising: waiting for a still IMU (or --init-moving-after)");
  } else if (out->status == Status::kInitializing) {
    node.set_health(kestrel::process_status_t::STATE_STARTING,
                    "awaiting SLAM's world (--await-world): STATE is INITIALIZING");
  } else if (out->status == Status::kDegraded) {
    node.set_health(kestrel::process_status_t::STATE_DEGRADED,
                    visual ? "visual only, no VO fused recently: predicting"
                           : "no VO fused recently: IMU only");
  } else {
    node.set_health(kestrel::process_status_t::STATE_RUNNING,
                    visual ? "visual only: the IMU has no gyro" : "");
  }
}

int run(const Options& o) {
  std::optional<transport::Node> node;
  node.emplace("estimator", o.lcm_url);  // UnavailableError: exit 4
  StateEstimator estimator(o.estimator);
  int64_t seq = 0;
  node->advertise(channel::kState);
  node->on_reset([&] {
    estimator.reset();
    seq = 0;
  });
  report_health(*node, estimator);
  auto publish = [&](const StepResult& r) {
    if (r.state)
      node->publish(channel::kState,
                    state_to_message(*r.state, estimator.mode(), o.estimator.filter, seq++));
  };
  // After each input: the health, and an input the gates refused goes back to Node as bad
  // input, which counts it in PROCESS_STATUS and logs it, rate-limited per channel. A restart
  // on a new time base is logged (the first few, then one in a hundred).
  int64_t refusals = 0, resyncs = 0;
  auto after_input = [&] {
    report_health(*node, estimator);
    if (estimator.resyncs() > resyncs) {
      resyncs = estimator.resyncs();
      if (resyncs <= 5 || resyncs % 100 == 0)
        spdlog::warn("restart #{} on a new time base: {}", resyncs, estimator.last_resync());
    }
    if (estimator.refusals() > refusals) {
      refusals = estimator.refusals();
      if (const auto& refused = estimator.last_rejection()) throw InputError(refused->what);
    }
  };

  node->subscribe<kestrel::imu_t>(channel::kImu, [&](const kestrel::imu_t& m) {
    const ImuReading r = imu_from_message(m, channel::kImu);  // throws: Node counts and logs
    const StepResult step = estimator.add_imu(r);
    if (step.verdict == Verdict::kDuplicate || step.verdict == Verdict::kOutOfOrder)
      spdlog::debug("IMU: sample at utime {} dropped (duplicate or out of order)", r.utime);
    publish(step);
    after_input();
  }, 400);
  node->subscribe<kestrel::vo_update_t>(channel::kVoUpdate, [&](const kestrel::vo_update_t& m) {
    // The library checks the update (and counts what it refuses, by reason).
    const VoUpdate u = vo_from_message(m, channel::kVoUpdate);
    const StepResult step = estimator.add_vo(u);
    if (step.verdict == Verdict::kDuplicate || step.verdict == Verdict::kOutOfOrder ||
        step.verdict == Verdict::kTooOld)
      spdlog::debug("VO_UPDATE: update at utime {} dropped (duplicate, out of order or too old)", u.utime);
    publish(step);
    after_input();
  });
  node->subscribe<kestrel::slam_correction_t>(channel::kSlamCorrection,
                                              [&](const kestrel::slam_correction_t& m) {
    const PoseCorrection c = correction_from_message(m, channel::kSlamCorrection);
    const int64_t aligned = estimator.counters().world_alignments;
    if (estimator.add_correction(c) == Verdict::kTooOld)
      spdlog::warn("SLAM_CORRECTION: correction for utime {} is outside the {} s history; dropped",
                   c.utime, o.estimator.history_s);
    if (estimator.counters().world_alignments > aligned)
      spdlog::warn("SLAM_CORRECTION: the first correction is far from this filter's world (a "
                   "restart while SLAM ran on?): the filter moved its world onto SLAM's");
    after_input();
  });

  const int code = node->spin();
  const EstimatorCounters c = estimator.counters();
  spdlog::info("{}IMU {} accepted, {} duplicate, {} out of order, {} gaps; VO {} applied, {} failed, "
               "{} gated ({} forced past the gate), {} dropped; corrections {} applied, {} too old, {} moved the world onto SLAM's; filter restarts {}",
               estimator.mode() == EstimatorMode::kVisualOnly ? "visual only; " : "",
               c.imu_accepted, c.imu_duplicate, c.imu_out_of_order, c.imu_gaps, c.vo_applied,
               c.vo_failed, c.vo_gated, c.vo_forced, c.vo_duplicate + c.vo_out_of_order + c.vo_too_old,
               c.corrections_applied, c.corrections_too_old, c.world_alignments, c.filter_failures);
  spdlog::info("refused: IMU {} invalid, {} beyond the accelerometer's range, {} beyond the gyro's, "
               "{} time jumps ({} new time bases); VO {} invalid, {} bad covariance, {} implausible "
               "motion, {} unknown reference, {} time jumps ({} new time bases); corrections {} "
               "invalid, {} bad covariance, {} implausible, {} time jumps",
               c.imu_invalid, c.imu_accel_range, c.imu_gyro_range, c.imu_time_jumps, c.imu_resyncs,
               c.vo_invalid, c.vo_bad_covariance, c.vo_implausible, c.vo_unknown_reference,
               c.vo_time_jumps, c.vo_resyncs, c.corrections_invalid, c.corrections_bad_covariance,
               c.corrections_implausible, c.corrections_time_jumps);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("estimator", "State estimator: IMU + VO_UPDATE + SLAM_CORRECTION -> STATE");
  Options options;
  app.add_option("--lcm-url", options.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  add_estimator_options(app, options.estimator);
  return app.run(argc, argv, [&] { return run(options); });
}
