#pragma once
// Every option of the estimator, with its default and unit. The processes expose each of
// them on the command line and in --config files (estimator/cli_options.h).

#include <Eigen/Core>

#include "estimator/filter.h"
#include "estimator/imu.h"
#include "common/gaussian/unscented.h"

namespace kestrel::estimator {

/// Where the noise of a visual-odometry measurement comes from.
struct VoNoiseOptions {
  enum class Source {
    kReported,  ///< the 6x6 covariance the VO sends with each update (times reported_scale)
    kConstant,  ///< the paper's constant model: constant_sigma, fitted by kestrel-fit-vo-noise
  };
  Source source = Source::kReported;
  double reported_scale = 1.0;  ///< multiplies the reported covariance
  /// Share of each update's noise that is its keyframe's own error, common to every update
  /// against that keyframe (the keyframe's feature positions and depths): that share is added
  /// once to the keyframe's clone, the rest is fused per update. 0 = every update independent
  /// (an anchor's own error is still common to the updates through it). The IMU filters only:
  /// the visual-only estimator does not model it.
  /// 0.4: kestrel-vo's share between updates one frame apart on the simulator's stata flights
  /// (`kestrel fit-vo-noise`; it fades to 0.02-0.17 over a hundred updates; on the two TUM
  /// clips 0.62 and 0.62).
  double keyframe_share = 0.4;
  /// Standard deviations of [dp (reference camera frame, m); dtheta (current camera, rad)].
  Eigen::Matrix<double, 6, 1> constant_sigma =
      (Eigen::Matrix<double, 6, 1>() << 0.005, 0.005, 0.008, 0.004, 0.004, 0.003).finished();
};

/// How the filter starts when no state is given: averaging the IMU over a still period, or,
/// when the vehicle is already moving, from the gravity direction with a wide covariance.
struct InitOptions {
  double duration_s = 0.5;        ///< IMU time averaged for attitude and gyro bias
  double max_accel_std = 0.3;     ///< m/s^2: above this the vehicle is moving; wait
  double max_gyro_std = 0.05;     ///< rad/s
  /// rad/s: a mean rate above this is motion, not gyro bias (a slow constant turn passes
  /// the spread tests above, and its rate taken for bias would stay wrong for good).
  double max_gyro_mean = 0.05;
  /// m/s: a VO update showing the camera faster than this against its reference frame (and
  /// beyond 3 sigma of its own noise) makes its window not still.
  double max_still_vo_speed = 0.1;
  /// Without a still window after this long, start on the move (0 = wait for a still vehicle
  /// however long it takes). Must be at least duration_s.
  double moving_start_after_s = 1.0;  ///< s
  // Prior standard deviations of a start on the move (the rest as for a still start). The
  // tilt comes from the window's mean specific force, which a mean acceleration of a tilts
  // by about a / g; the velocity is unknown until the visual odometry has seen motion.
  double moving_sigma_tilt = 0.15;       ///< rad: a mean acceleration of up to ~1.5 m/s^2
  double moving_sigma_velocity = 1.5;    ///< m/s
  double moving_sigma_gyro_bias = 0.02;  ///< rad/s: the bias is not measured at all
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< world frame origin choice, m
  double yaw = 0.0;               ///< rad: yaw is unobservable, so it is given
  // Prior standard deviations of the initial state. A start on the move publishes no state
  // until the visual odometry has measured its velocity and tilt as well as sigma_velocity and
  // sigma_tilt here (a controller would act on a velocity of 0 +- 1.5 m/s, and the first VO
  // update would move the state by all the vehicle flew since the start).
  double sigma_position = 1e-3;   ///< m
  double sigma_velocity = 0.05;   ///< m/s
  double sigma_tilt = 0.02;       ///< rad, roll and pitch
  double sigma_yaw = 1e-3;        ///< rad
  double sigma_gyro_bias = 5e-3;  ///< rad/s (after subtracting the averaged rate)
  double sigma_accel_bias = 0.1;  ///< m/s^2
};

/// Which estimator runs: the IMU filter needs a gyro and an accelerometer; without a gyro (a
/// Kinect's accelerometer, a TUM recording) the state comes from the visual odometry alone.
enum class EstimatorMode {
  kAuto,        ///< decided by the first IMU reading (visual-only without a gyro, or without any IMU)
  kImu,         ///< the IMU filter (EKF or UKF); IMU readings without a gyro are refused
  kVisualOnly,  ///< the visual-only estimator (visual_only.h), whatever the IMU carries
};

/// The visual-only estimator's motion model between frames: constant velocity and angular
/// velocity, driven by white acceleration and angular acceleration of these densities.
struct VisualOnlyOptions {
  double accel_noise_density = 1.0;          ///< m/s^2/sqrt(Hz)
  double angular_accel_noise_density = 1.0;  ///< rad/s^2/sqrt(Hz)
  double sigma_angular_velocity = 1.0;       ///< rad/s, prior of the first frame
  /// The accelerometer as a tilt sensor after the start: the acceleration a reading cannot
  /// tell from gravity (m/s^2); 0 (the default) = level only at the start. Off because a
  /// Kinect's accelerometer is a worse tilt reference than its VO over minutes: on fr1_xyz and
  /// fr1_rpy 0.5 made the state's ATE 12 % and 26 % worse (its axes are off by up to 30 %,
  /// drivers/tum/README.md), and SLAM's corrections keep the tilt where loops close.
  double gravity_sigma = 0.0;
  /// In mode kAuto, VO updates spanning this long with no IMU reading at all select the
  /// visual-only estimator (a source without an IMU).
  double no_imu_after_s = 1.0;  ///< s
};

/// What an input may say before either estimator takes it (estimator/input_gate.h). The
/// sensor bounds are a typical MEMS IMU's full scale; a reading beyond them is no measurement
/// (a spike, a corrupt sample) and is refused, not clipped.
struct InputGateOptions {
  double max_accel = 16.0 * kStandardGravity;  ///< m/s^2 per axis: +-16 g (156.9 m/s^2)
  double max_gyro = 2000.0 * 3.14159265358979323846 / 180.0;  ///< rad/s per axis: +-2000 deg/s (34.9 rad/s)
  /// s: a stamp further than this from the newest of its stream, ahead or back, is held
  /// rather than taken: an outlier, or the first of a new time base (a driver restarted).
  double max_time_jump_s = 1.0;
  /// Held stamps in a row, each within max_time_jump_s after the one before, that make a new
  /// time base: the estimator then restarts on it (its old states mean nothing there).
  int resync_samples = 10;
  /// The body's motion in a VO update, over the time between its frames: faster than this
  /// is no vehicle's (the tests' aggressive motion stays under 3 m/s and 2 rad/s).
  double vo_max_speed = 25.0;  ///< m/s
  double vo_max_rate = 10.0;   ///< rad/s
  /// m: a SLAM correction further than this from the state at its time is refused (a loop
  /// closure moves metres; a first correction moving the world moves across the map).
  double correction_max_jump_m = 100.0;
};

struct EstimatorOptions {
  EstimatorMode mode = EstimatorMode::kAuto;
  InputGateOptions gates;
  VisualOnlyOptions visual_only;
  FilterKind filter = FilterKind::kEkf;
  gaussian::UnscentedParams unscented;
  ImuNoise imu;
  double gravity = kStandardGravity;  ///< m/s^2
  VoNoiseOptions vo_noise;
  /// Gate on the squared Mahalanobis distance of a VO innovation (chi^2, 6 dof); 0 = off.
  /// 30 lets through all but 1 in 25,000 correct measurements.
  double vo_gate_chi2 = 30.0;
  /// After this many VO updates in a row refused by the gate, the next one is fused without
  /// it: ten outliers in a row (a third of a second) are less likely than a filter that has
  /// gone wrong (e.g. a gyro bias mistaken at start-up) and would otherwise never recover.
  /// 0 = never.
  int vo_max_gated_in_row = 10;
  /// The same for SLAM corrections; off by default: a loop closure may move the state far.
  double correction_gate_chi2 = 0.0;
  /// The first SLAM correction after the start further than this from the filter (chi^2, 6
  /// dof) says the filter's world is not SLAM's: the filter was restarted while SLAM's map,
  /// anchored to the filter that ran before, lived on. The filter then moves its world onto
  /// SLAM's (a turn about z and a shift) instead of fusing the correction; 0 = never. A filter
  /// that started with SLAM shares its world and is within a few units of chi^2. A filter told
  /// to await SLAM's world (await_world_s > 0) takes it from the first correction whatever its
  /// chi^2: it was started to join a map, and a hover near its own origin can put SLAM's world
  /// within the bound (a 1.5 m offset against SLAM's 5 cm is chi^2 ~900) where fusing the
  /// correction into a millimetre-sure filter would leave it where it was.
  double world_align_chi2 = 1000.0;
  /// After the start, states are published as INITIALIZING (a pose in this filter's own world,
  /// not to be flown on) until a SLAM correction has been taken or this long (s, sensor time)
  /// has passed since the first: a filter restarted in flight flies on the map's world from its
  /// first usable state (kestrel-slam sends it for the next frame on seeing the new filter's
  /// first state). 0 = publish usable states at once (no SLAM, or offline runs).
  double await_world_s = 0.0;
  /// Used for a correction that carries no covariance (all zero): sigmas of [dp; dtheta].
  double correction_sigma_position = 0.05;  ///< m
  double correction_sigma_rotation = 0.02;  ///< rad
  /// How far back states and measurements are kept: a measurement older than this is dropped.
  double history_s = 3.0;
  /// An IMU interval longer than this is a gap: readings are held and the gap noise is added.
  double max_imu_dt_s = 0.02;
  /// Without an accepted VO update for this long the state is DEGRADED (IMU only).
  double vo_timeout_s = 0.5;
  InitOptions init;
};

}  // namespace kestrel::estimator
