#pragma once
// The SLAM process's message conversions (process side: the library knows no LCM):
// vo_update_t -> VoMotion, and the library's graph -> slam_graph_t / slam_correction_t.
//
// Frames: SLAM_GRAPH carries T_world_camera of each keyframe; SLAM_CORRECTION carries
// T_world_body = T_world_camera * T_body_camera^-1 of the newest keyframe (or of a frame since
// it, for a restarted estimator: slam_adapter.h), world being the body frame at the first
// keyframe (odometry_chain.h).
//
// Published keyframe ids and graph revisions count from the session's first keyframe: its
// utime (µs) plus the library's own index or revision. A keyframe keeps its own session's base
// (a saved map's keyframes keep the ids the flight that made them published); the revision
// counts from the newest session's base, or from this process's first frame while that session
// has no keyframe yet, so a process started on a saved map publishes after everything the
// flights before it did, even one that ended without saving. A SLAM process restarted in flight
// (a new session) therefore never reuses an id of the one before and never goes back in
// revision, so the mapper keeps the old session's keyframes where they were and adds the new
// ones (the library's indices restart at 0; a session has fewer keyframes and revisions than
// microseconds).

#include <optional>

#include "kestrel/slam_correction_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "slam/backend/odometry_chain.h"
#include "slam/backend/slam.h"

namespace kestrel::slam {

/// Throws InputError naming `channel` for a pose that is not a finite rigid transform.
VoMotion motion_from_message(const kestrel::vo_update_t& m, const char* channel);

/// The published id of a keyframe and revision of a graph (see above).
int64_t published_id(const Slam& slam, int64_t keyframe_index);
int64_t published_revision(const Slam& slam);

/// The keyframes made while the camera is not yet placed in a saved map (ids from
/// Slam::provisional_from(), poses in their own frame, no edges), for SLAM_GRAPH_UNPLACED: the
/// mapper keeps their frames until the placement joins them to the map: the newest
/// `max_keyframes` (the mapper keeps no more). Empty when none.
kestrel::slam_graph_t unplaced_graph_message(const Slam& slam, size_t max_keyframes = 300);

kestrel::slam_graph_t graph_message(const Slam& slam);

/// The covariance of T_world_body in pose_t's convention ([dp in world; dtheta in body]) from
/// that of T_world_camera as the optimiser gives it (marginals.h: right perturbation
/// [rho; phi] in the camera frame), with T_world_body = T_world_camera * T_body_camera^-1.
Matrix6d body_covariance(const Eigen::Isometry3d& T_world_body, const Eigen::Isometry3d& T_body_camera,
                         const Matrix6d& camera_covariance);

/// A frame after SLAM's reference (Slam::reference()), for a correction at that frame: its pose in SLAM's
/// odometry frame (the one the keyframes have), its camera mounting, and the covariance of the
/// odometry's motion from the reference to it (right perturbation [rho; phi],
/// OdometryChain::relative_covariance).
struct FrameSinceKeyframe {
  int64_t utime = 0;
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  Matrix6d odometry_covariance = Matrix6d::Zero();
};

/// Where the graph was anchored in the estimator's world (SlamAdapter: Slam::change_world onto a
/// STATE): the body's pose there and that state's covariance in pose_t's convention. The whole
/// graph shares the anchor's error, moved rigidly: its attitude error turns every pose about the
/// anchor, so it weighs more the further a pose is from it (anchor_covariance_at).
struct WorldAnchor {
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();
};

/// The anchor's error as the error of another pose of the graph, T_world_body, both in pose_t's
/// convention: dp = dp_anchor - [p - p_anchor]x R_anchor dtheta_anchor,
/// dtheta = R^T R_anchor dtheta_anchor.
Matrix6d anchor_covariance_at(const WorldAnchor& anchor, const Eigen::Isometry3d& T_world_body);

/// The correction for SLAM's reference (the newest keyframe, or the frame re-anchored on a
/// covering keyframe: Slam::reference()), or, given `frame`, for that later frame
/// (Slam::world_pose: the reference's optimised pose composed with the odometry since, whose
/// covariance frame->odometry_covariance is). keyframe_id names the reference's keyframe. Its
/// covariance is the optimiser's marginal of that keyframe (Slam::reference_marginal) and the
/// re-anchoring's, carried to the frame with the odometry's own added, then to the body frame
/// in pose_t's convention; when there is no marginal, a diagonal one of the given standard
/// deviations (metres, radians) stands for the keyframe's. The marginal is relative to the
/// graph's fixed first keyframe; given `anchor`, that keyframe's own error in the estimator's
/// world (the anchoring state's) is added. The slam must have a keyframe.
kestrel::slam_correction_t correction_message(const Slam& slam, double sigma_translation_m,
                                              double sigma_rotation_rad,
                                              const std::optional<FrameSinceKeyframe>& frame = std::nullopt,
                                              const std::optional<WorldAnchor>& anchor = std::nullopt);

}  // namespace kestrel::slam
