#pragma once
// What the odometry assumes about the camera that VoOptions alone do not say: its timing and
// the errors its noise model leaves out. VoOptions{} is the simulator's camera (global
// shutter, depth and colour captured together, covariance floors fitted on its rendered
// frames); a Kinect (v1) reads its colour image row by row and its depth at another time,
// and errs more than its pixel and depth noise say (misregistration, timing).
//
// The Kinect's values were measured on TUM's freiburg1 recordings (vo/README.md, "Sensor
// timing" and "Covariance"); they are one calibration of the sensor, chosen by sweeps scored
// on both sequences, not per sequence. Every frame names its sensor's model (RgbdFrame::sensor,
// set by the source and kept in logs), and profile_of_sensor() maps it to a profile; `kestrel
// vo --sensor` and `kestrel slam --sensor` override it.

#include <optional>
#include <string>

#include "vo/options.h"

namespace kestrel::vo {

enum class SensorProfile {
  kSimulator,  ///< VoOptions{} as they are
  kKinect1,    ///< the freiburg1 Kinect: rolling shutter, depth latency, larger covariance
};

/// The Kinect's model:
/// - a rolling colour shutter, first-to-last row time as the odometry uses it;
/// - the depth captured at the stamps' difference minus an extra latency of the depth image:
///   the stamps are arrival times, and the depth arrives later after its capture than the
///   colour image does (fr1_xyz's stamps put depth 8 to 16 ms before colour, fr1_rpy's 0 to
///   14 ms after; the best fixed offsets of the two recordings differ by a similar 20 ms:
///   about -25 ms on fr1_xyz, -5 ms on fr1_rpy), and 15 ms fits both (vo/README.md);
/// - what the odometry's noise model leaves out on this sensor (CovarianceOptions): per-frame
///   floors 1.0 mm / 0.002 rad (they also absorb the ground truth's own orientation jitter,
///   ~0.1 degrees) and 0.10 m / 0.085 rad per radian the camera turned, fitted to how the
///   error of fr1's motions grows with the rotation summed over 1 to 32 frames (the same
///   factors on both recordings within 25 %); mean NEES against the ground truth 5.4 / 6.6 on
///   fr1_xyz / fr1_rpy (vo/README.md, "Covariance").
/// - a heavier dense depth term (DenseOptions::weight 2.0 against the simulator's 0.4): what
///   is left of fr1's frame-to-frame error is per-frame pose noise of the colour features,
///   coupled to rotation (it alternates from frame to frame and follows the frame's rotation
///   error), which the depth, constraining translation directly, pulls down; the weight trades
///   it against the 1 s drift and the ATE, and 2.0 gives the largest smallest margin to issue
///   4's targets over both recordings (vo/README.md, "Measured", 26 Nov 13:30).
constexpr double kKinect1RollingShutterReadoutS = 0.015;
constexpr double kKinect1DepthExtraLatencyS = 0.015;
constexpr double kKinect1TranslationFloorM = 0.001;
constexpr double kKinect1RotationFloorRad = 0.002;
constexpr double kKinect1TranslationPerRadM = 0.10;
constexpr double kKinect1RotationPerRad = 0.085;
constexpr double kKinect1DenseWeight = 2.0;
/// The near-keyframe rule (KeyframeOptions::min_inliers_to_keep_near), as the simulator's: a
/// hovering Kinect keeps its keyframe. On fr1 it makes the VO better on every column but one
/// (ATE 1.13 -> 0.94 cm on fr1_xyz, 2.53 -> 2.17 cm on fr1_rpy) and the estimator's STATE too.
/// It was off until SLAM's loops on a Kinect took their real noise (kKinect1LoopRotationFloorRad,
/// slam/place/loop_verifier.h): fr1_xyz's one loop, 1.7 cm and 1 degree off, had left SLAM's
/// ATE above the better VO's (0.97 against 0.94 cm; issue 6 asks SLAM to be no worse).
constexpr int kKinect1MinInliersToKeepNear = 150;

/// `options` with the profile's timing and floors set (kSimulator: unchanged).
VoOptions with_sensor(SensorProfile profile, VoOptions options);

/// "simulator" or "kinect1" (sensor_model::k*, the names frames carry).
std::string to_string(SensorProfile profile);

/// The profile for frames of `sensor_model` (RgbdFrame::sensor): kinect1's for "kinect1", the
/// simulator's for any other name, "" (unknown) included.
SensorProfile profile_of_sensor(const std::string& sensor_model);
/// The profile named `name` (as to_string() writes it), or nothing.
std::optional<SensorProfile> parse_sensor_profile(const std::string& name);

}  // namespace kestrel::vo
