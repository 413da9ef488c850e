// kestrel-estimate: the estimator in process over an LCM log's IMU, VO_UPDATE and
// SLAM_CORRECTION messages, written as a TUM trajectory of T_world_body (README.md).

#include <spdlog/spdlog.h>

#include <iostream>

#include "common/cli.h"
#include "common/error.h"
#include "estimator/cli_options.h"
#include "estimator/log_run.h"

namespace {

using namespace kestrel;
using namespace kestrel::estimator;

struct Options {
  std::string log;
  std::string out;
  LogChannels channels;
  EstimatorOptions estimator;
  double skip_s = 0.0;
};

int run(const Options& o) {
  const LogRunResult r = run_log(o.log, o.estimator, o.channels, o.skip_s);
  if (!r.skips.damage.empty()) spdlog::warn("{}", r.skips.damage);
  if (r.skips.rejected > 0)
    spdlog::warn("{} messages skipped; the first: {}", r.skips.rejected, r.skips.first_reason);
  const bool visual = r.mode == EstimatorMode::kVisualOnly;
  if (r.trajectory.empty() && visual)
    throw InputError(o.log + ": the visual-only estimator never started (no successful VO update "
                     "among " + std::to_string(r.vo_messages) + ")");
  if (r.trajectory.empty())
    throw InputError(o.log + ": the filter never initialised (" + std::to_string(r.imu_messages) +
                     " IMU messages; it needs " + std::to_string(o.estimator.init.duration_s) +
                     " s of a still IMU, or --init-moving-after)");
  write_tum_trajectory(o.out, r.trajectory);
  const EstimatorCounters& c = r.counters;
  std::cout << "estimator: " << (visual ? "visual only (the IMU has no gyro)" : "IMU filter") << "\n"
            << "states written: " << r.trajectory.size() << " to " << o.out << "\n"
            << "IMU messages: " << r.imu_messages << " (" << c.imu_duplicate << " duplicate, "
            << c.imu_out_of_order << " out of order, " << c.imu_gaps << " gaps)\n"
            << "VO updates: " << r.vo_messages << " (" << c.vo_applied << " applied, "
            << c.vo_failed << " failed, " << c.vo_gated << " gated, " << c.vo_forced
            << " forced past the gate, "
            << c.vo_duplicate + c.vo_out_of_order + c.vo_too_old + c.vo_before_init
            << " dropped)\n"
            << "SLAM corrections: " << r.correction_messages << " (" << c.corrections_applied
            << " applied, " << c.corrections_too_old << " too old, " << c.world_alignments
            << " moved the world onto SLAM's)\n"
            << "refused by the gates: IMU " << c.imu_accel_range + c.imu_gyro_range << " beyond the sensor's range, "
            << c.imu_time_jumps << " time jumps (" << c.imu_resyncs << " new time bases); VO "
            << c.vo_implausible << " implausible motion, " << c.vo_unknown_reference << " unknown reference, "
            << c.vo_bad_covariance << " bad covariance, " << c.vo_time_jumps << " time jumps ("
            << c.vo_resyncs << " new time bases); corrections " << c.corrections_implausible
            << " implausible, " << c.corrections_bad_covariance << " bad covariance, "
            << c.corrections_time_jumps << " time jumps\n"
            << "messages skipped: " << r.skips.rejected << "\n"
            << "filter restarts: " << c.filter_failures << "\n"
            << "started: " << (visual ? "on the first VO update" : c.moving_starts > 0 ? "on the move" : "still") << " at "
            << r.trajectory.poses().front().utime << "\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("estimate",
                        "Run the state estimator over an LCM log and write its TUM trajectory");
  Options o;
  app.add_option("--log", o.log, "LCM log with IMU and VO_UPDATE (and SLAM_CORRECTION)")
      ->required()->check(CLI::ExistingFile);
  app.add_option("--out", o.out, "TUM trajectory file to write (T_world_body)")->required();
  app.add_option("--imu-channel", o.channels.imu, "IMU channel")->capture_default_str();
  app.add_option("--vo-channel", o.channels.vo, "VO channel")->capture_default_str();
  app.add_option("--correction-channel", o.channels.correction, "SLAM correction channel")
      ->capture_default_str();
  app.add_option("--skip", o.skip_s,
                 "Leave out the log's first seconds: the estimator starts in flight, s")
      ->check(CLI::Range(0.0, 1e6))->capture_default_str();
  add_estimator_options(app, o.estimator);
  return app.run(argc, argv, [&] { return run(o); });
}
