#include "estimator/cli_options.h"

#include <map>
#include <string>

namespace kestrel::estimator {
namespace {

// CLI11 binds vectors, not Eigen types: shows an Eigen vector as its default.
std::string joined(const double* v, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += (i ? "," : "") + CLI::detail::to_string(v[i]);
  return out;
}

}  // namespace

void add_estimator_options(CLI::App& app, EstimatorOptions& o) {
  static const std::map<std::string, FilterKind> kFilters{{"ekf", FilterKind::kEkf},
                                                          {"ukf", FilterKind::kUkf}};
  static const std::map<std::string, VoNoiseOptions::Source> kSources{
      {"reported", VoNoiseOptions::Source::kReported},
      {"constant", VoNoiseOptions::Source::kConstant}};
  static const std::map<std::string, EstimatorMode> kModes{
      {"auto", EstimatorMode::kAuto}, {"imu", EstimatorMode::kImu},
      {"visual", EstimatorMode::kVisualOnly}};
  const CLI::Range non_negative(0.0, 1e9);
  const CLI::Range positive(1e-12, 1e9);

  app.add_option("--mode", o.mode,
                 "auto: the IMU filter if the IMU has a gyro, else the visual odometry alone; "
                 "imu: the IMU filter only; visual: the visual odometry alone")
      ->transform(CLI::CheckedTransformer(kModes, CLI::ignore_case))
      ->default_str("auto");
  app.add_option("--visual-accel-noise", o.visual_only.accel_noise_density,
                 "Visual only: white acceleration of the constant-velocity model, m/s^2/sqrt(Hz)")
      ->check(positive)->capture_default_str();
  app.add_option("--visual-angular-accel-noise", o.visual_only.angular_accel_noise_density,
                 "Visual only: white angular acceleration, rad/s^2/sqrt(Hz)")
      ->check(positive)->capture_default_str();
  app.add_option("--visual-gravity-sigma", o.visual_only.gravity_sigma,
                 "Visual only: acceleration an accelerometer reading cannot tell from gravity, "
                 "m/s^2 (0 = level only at the start)")
      ->check(non_negative)->capture_default_str();
  app.add_option("--no-imu-after", o.visual_only.no_imu_after_s,
                 "--mode auto: VO updates this long with no IMU at all select the visual odometry alone, s")
      ->check(positive)->capture_default_str();
  app.add_option("--filter", o.filter, "State filter: ekf (Appendix A) or ukf (Appendix B)")
      ->transform(CLI::CheckedTransformer(kFilters, CLI::ignore_case))
      ->default_str("ekf");
  app.add_option("--vo-noise", o.vo_noise.source,
                 "VO measurement noise: the covariance each update reports, or the constant "
                 "model (--vo-sigma, fitted by kestrel fit-vo-noise)")
      ->transform(CLI::CheckedTransformer(kSources, CLI::ignore_case))
      ->default_str("reported");
  app.add_option("--vo-scale", o.vo_noise.reported_scale, "Multiplies the reported VO covariance")
      ->check(positive)->capture_default_str();
  app.add_option("--vo-keyframe-share", o.vo_noise.keyframe_share,
                 "Share of each VO update's noise that is its keyframe's own error, common to every "
                 "update against that keyframe: fused once per keyframe, not once per update (the IMU "
                 "filter; the visual-only mode does not model it)")
      ->check(CLI::Range(0.0, 0.99))->capture_default_str();
  app.add_option_function<std::vector<double>>(
         "--vo-sigma",
         [&o](const std::vector<double>& v) {
           o.vo_noise.constant_sigma = Eigen::Map<const Eigen::Matrix<double, 6, 1>>(v.data());
         },
         "Constant VO model: sigmas of dx,dy,dz (m, reference camera),rx,ry,rz (rad)")
      ->expected(6)->delimiter(',')->check(positive)
      ->default_str(joined(o.vo_noise.constant_sigma.data(), 6));
  app.add_option("--vo-gate", o.vo_gate_chi2, "Chi-square (6 dof) gate on VO innovations, 0 = off")
      ->check(non_negative)->capture_default_str();
  app.add_option("--vo-max-gated-in-row", o.vo_max_gated_in_row,
                 "After this many gated VO updates in a row, fuse the next ungated (0 = never)")
      ->check(CLI::Range(0, 1000000))->capture_default_str();
  app.add_option("--correction-gate", o.correction_gate_chi2,
                 "Chi-square (6 dof) gate on SLAM corrections, 0 = off")
      ->check(non_negative)->capture_default_str();
  app.add_option("--world-align", o.world_align_chi2,
                 "A first SLAM correction further than this (chi-square, 6 dof) moves the filter's "
                 "world onto SLAM's: a filter restarted while SLAM ran on (0 = never)")
      ->check(non_negative)->capture_default_str();
  app.add_option("--await-world", o.await_world_s,
                 "After the start, STATE is INITIALIZING until a SLAM correction sets the world or "
                 "this long has passed, s (0 = usable at once; kestrel launch sets 1)")
      ->check(CLI::Range(0.0, 60.0))->capture_default_str();
  app.add_option("--correction-sigma-position", o.correction_sigma_position,
                 "m, for a correction without covariance")->check(positive)->capture_default_str();
  app.add_option("--correction-sigma-rotation", o.correction_sigma_rotation,
                 "rad, for a correction without covariance")->check(positive)->capture_default_str();
  app.add_option("--history", o.history_s, "Seconds of states kept for late measurements")
      ->check(CLI::Range(0.05, 60.0))->capture_default_str();
  app.add_option("--max-imu-dt", o.max_imu_dt_s, "An IMU interval longer than this is a gap, s")
      ->check(positive)->capture_default_str();
  app.add_option("--vo-timeout", o.vo_timeout_s, "DEGRADED after this long without VO, s")
      ->check(positive)->capture_default_str();
  app.add_option("--imu-max-accel", o.gates.max_accel,
                 "Accelerometer range per axis, m/s^2 (16 g): a reading beyond it is refused")
      ->check(positive)->capture_default_str();
  app.add_option("--imu-max-rate", o.gates.max_gyro,
                 "Gyro range per axis, rad/s (2000 deg/s): a reading beyond it is refused")
      ->check(positive)->capture_default_str();
  app.add_option("--max-time-jump", o.gates.max_time_jump_s,
                 "A stamp further than this from the newest of its stream, ahead or back, is held "
                 "as an outlier or a new time base, s")
      ->check(CLI::Range(0.01, 1e6))->capture_default_str();
  app.add_option("--resync-samples", o.gates.resync_samples,
                 "Held stamps in a row, each within --max-time-jump of the one before, that restart "
                 "the estimator on their new time base (at least 2: one is the outlier it guards against)")
      ->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--vo-max-speed", o.gates.vo_max_speed,
                 "A VO motion faster than this over the time between its frames is refused, m/s")
      ->check(positive)->capture_default_str();
  app.add_option("--vo-max-rate", o.gates.vo_max_rate,
                 "A VO rotation faster than this over the time between its frames is refused, rad/s")
      ->check(positive)->capture_default_str();
  app.add_option("--correction-max-jump", o.gates.correction_max_jump_m,
                 "A SLAM correction further than this from the state at its time is refused, m")
      ->check(positive)->capture_default_str();
  app.add_option("--gyro-noise", o.imu.gyro_noise_density, "rad/s/sqrt(Hz)")->check(positive)->capture_default_str();
  app.add_option("--accel-noise", o.imu.accel_noise_density, "m/s^2/sqrt(Hz)")->check(positive)->capture_default_str();
  app.add_option("--gyro-bias-walk", o.imu.gyro_bias_random_walk, "rad/s^2/sqrt(Hz)")->check(positive)->capture_default_str();
  app.add_option("--accel-bias-walk", o.imu.accel_bias_random_walk, "m/s^3/sqrt(Hz)")->check(positive)->capture_default_str();
  app.add_option("--ukf-alpha", o.unscented.alpha, "UKF sigma-point spread")->check(positive)->capture_default_str();
  app.add_option("--ukf-beta", o.unscented.beta, "UKF prior-distribution weight")->check(non_negative)->capture_default_str();
  app.add_option("--ukf-kappa", o.unscented.kappa, "UKF secondary scaling")->capture_default_str();
  app.add_option("--init-duration", o.init.duration_s, "Still IMU time averaged to start, s")
      ->check(positive)->capture_default_str();
  app.add_option("--init-moving-after", o.init.moving_start_after_s,
                 "Without a still IMU window for this long, start on the move with a wide "
                 "covariance (0 = wait for a still vehicle), s")
      ->check(non_negative)->capture_default_str();
  app.add_option("--init-yaw", o.init.yaw, "Yaw of the initial attitude (unobservable), rad")
      ->capture_default_str();
  app.add_option_function<std::vector<double>>(
         "--init-position",
         [&o](const std::vector<double>& v) { o.init.position = Eigen::Map<const Eigen::Vector3d>(v.data()); },
         "Initial position x,y,z, m")
      ->expected(3)->delimiter(',')->default_str(joined(o.init.position.data(), 3));
}

}  // namespace kestrel::estimator
