#pragma once
// Geometric verification of a loop-closure candidate (PAPER.md section 3): ORB matches that
// pass the ratio test, a 3-D-3-D RANSAC on the points both keyframes measured, then two-frame
// bundle adjustment (two_view_adjustment.h) to refine the relative pose and give its
// uncertainty. A candidate is accepted only with enough inliers that reproject well after the
// adjustment and determine the rotation (not all near one line).
//
// The accepted constraint is a pose-graph edge from the candidate keyframe to the query:
// T_candidate_query and its information matrix in the pose graph's error convention
// (slam/posegraph/spaces.h).

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <string>

#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "slam/place/frame_features.h"
#include "slam/place/two_view_adjustment.h"
#include "sensors/sensor_profile.h"

namespace kestrel::slam {

struct VerificationOptions {
  double ratio = 0.6;               ///< best / second-best Hamming distance at most
  int max_hamming = 64;             ///< and the best at most this (of 256 bits)
  int min_inliers = 10;             ///< after RANSAC and after the adjustment
  double min_inlier_fraction = 0.25;  ///< of the ratio-test matches with depth in both frames
  int ransac_iterations = 300;
  double inlier_floor_m = 0.02;     ///< 3-D distance tolerance at short range
  double inlier_sigmas = 3.0;       ///< tolerance in depth-noise standard deviations
  double depth_noise = 1.4e-3;      ///< sigma_z = depth_noise * z^2, metres
  /// Inliers must span this (standard deviation along their 2nd principal axis; 0 = no test).
  /// A loop has no prior to check it against: a few inliers close together are where wrong
  /// loops came from (TUM fr1_xyz: 10 inliers spanning 14.5 cm, 4.4 cm and 1.3 degrees off).
  double min_spread_m = 0.15;
  /// The adjustment must determine the relative rotation to this (standard deviation about its
  /// worst-determined axis, before the floors below): inliers near a line leave the rotation
  /// about it free. A precision rather than a size, so it holds at any range and count: a wall
  /// half a metre away gives hundreds of inliers spanning 7-14 cm that fix the rotation to
  /// 0.1-0.5 degrees. 1 degree, the Kinect's own per-loop error (kinect1.yaml).
  double max_rotation_sigma_rad = kPi / 180.0;
  double max_pixel_error = 3.0;     ///< an inlier's reprojection error after the adjustment
  double max_rms_px = 2.0;
  double translation_sigma_floor_m = 0.01;  ///< added to the adjustment's covariance
  double rotation_sigma_floor_rad = 0.005;  ///< (the simulator's camera; a Kinect's below)
  TwoViewOptions adjustment;
};

/// `options` for a loop between keyframes of cameras `a` and `b`: the rotation floor is the
/// largest of options.rotation_sigma_floor_rad and the two profiles' loop floors
/// (sensors/profiles/*.yaml, slam.loop_rotation_floor_deg). Why a camera has one: on freiburg1
/// every verified Kinect loop is 0.8 to 1.2 degrees off the motion capture (7 loops over fr1_xyz
/// and fr1_rpy), about as far as the odometry's own two-frame estimate between the same frames
/// (0.6 to 1.0 degrees): per-frame errors of the sensor (colour/depth misregistration, timing)
/// that a chain of frame-to-frame motions partly cancels but a two-frame measurement carries
/// whole. With the simulator's 0.005 rad such a loop outweighed the odometry between its ends
/// (slam/README.md, "Loop noise").
VerificationOptions loop_verification(VerificationOptions options, const sensors::SensorProfile& a,
                                      const sensors::SensorProfile& b);

struct LoopConstraint {
  bool accepted = false;
  std::string reason;               ///< why not, when rejected
  Eigen::Isometry3d T_candidate_query = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();  ///< of the pose-graph edge candidate -> query
  int matches = 0;                  ///< ratio-test matches with depth in both frames
  int inliers = 0;                  ///< after the adjustment
  /// The consensus inliers' spread (VerificationOptions::min_spread_m), before the adjustment;
  /// 0 when verification stopped earlier. Verified with min_spread_m 0, the same frames and seed
  /// pass with a positive bound exactly when this reaches it.
  double spread_m = 0.0;
  double rms_px = 0.0;
};

/// Verifies `candidate` as an earlier view of the place `query` sees. `seed` drives RANSAC.
LoopConstraint verify_loop(const FrameFeatures& query, const FrameFeatures& candidate,
                           const VerificationOptions& options, uint64_t seed);

/// The information of the pose-graph edge (g2o's error convention) whose measurement is
/// Z = T_a_b^-1, given the covariance of a right perturbation of T_a_b (TwoViewResult).
Matrix6d edge_information(const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance_right_T_a_b);

}  // namespace kestrel::slam
