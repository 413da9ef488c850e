#include "slam/slam_adapter.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"
#include "sensors/builtin_profiles.h"

namespace kestrel::slam {

SlamAdapter::SlamAdapter(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary,
                         const AdapterOptions& adapter)
    : options_(adapter), slam_(options, std::move(vocabulary)) {
  if (adapter.buffer_frames < 1) throw std::invalid_argument("slam: buffer_frames must be >= 1");
}

SlamAdapter::SlamAdapter(std::shared_ptr<const SlamMap> map, const SlamOptions& options, const AdapterOptions& adapter)
    : options_(adapter), slam_(std::move(map), options), map_loaded_(!slam_.keyframes().empty()) {
  if (adapter.buffer_frames < 1) throw std::invalid_argument("slam: buffer_frames must be >= 1");
  // A map of nothing has no world to bring: the graph is anchored on STATE as without one.
  anchored_ = map_loaded_;
}

void SlamAdapter::reset() {
  slam_.reset();
  chain_.reset();
  frames_.clear();
  poses_.clear();
  last_processed_utime_ = 0;
  lost_break_ = false;
  anchored_ = map_loaded_;
  anchor_.reset();
  states_.clear();
  recent_.clear();
  odometry_fix_ = Eigen::Isometry3d::Identity();
  last_pose_.reset();
  previous_chained_.reset();
  reference_pose_.reset();
  bridges_ = 0;
  last_state_seq_ = -1;
  restart_correction_due_ = false;
  estimator_restarts_ = 0;
  keyframe_up_.clear();
  levellings_ = levels_refused_ = 0;
}

void SlamAdapter::trim_frames() {
  while (static_cast<int>(frames_.size()) > options_.buffer_frames) frames_.erase(frames_.begin());
}

void SlamAdapter::drop_poses(std::map<int64_t, ChainedPose>::iterator end) {
  for (auto it = poses_.begin(); it != end; ++it) lost_break_ |= it->second.pose.broken;
  poses_.erase(poses_.begin(), end);
}

AdapterOutputs SlamAdapter::on_frame(const kestrel::rgbd_frame_t& frame) {
  if (frame.utime <= last_processed_utime_) {
    throw InputError(options_.camera_channel + ": frame " + std::to_string(frame.utime) +
                     " is older than one already processed");
  }
  const auto pose = poses_.find(frame.utime);
  if (pose == poses_.end()) {
    frames_[frame.utime] = frame;
    trim_frames();
    return {};
  }
  const ChainedPose p = pose->second;
  poses_.erase(pose);
  drop_poses(poses_.lower_bound(frame.utime));  // older poses will get no frame now
  return process(frame, p);
}

AdapterOutputs SlamAdapter::on_vo_update(const kestrel::vo_update_t& update) {
  const VoMotion motion = motion_from_message(update, options_.vo_channel.c_str());
  std::optional<OdometryPose> pose;
  try {
    pose = chain_.add(motion);
  } catch (const InputError& e) {
    throw InputError(options_.vo_channel + ": " + e.what());
  }
  if (!pose) return {};
  ChainedPose chained{*pose};
  if (previous_chained_ && !pose->broken) {
    chained.previous_utime = previous_chained_->utime;
    chained.T_previous_current = previous_chained_->T_odom_camera.inverse() * pose->T_odom_camera;
  }
  previous_chained_ = *pose;
  const auto frame = frames_.find(update.utime);
  if (frame == frames_.end()) {
    poses_[update.utime] = chained;
    if (static_cast<int>(poses_.size()) > options_.buffer_frames) drop_poses(std::next(poses_.begin()));
    return {};
  }
  const kestrel::rgbd_frame_t message = std::move(frame->second);
  frames_.erase(frames_.begin(), std::next(frame));  // older frames will get no pose now
  return process(message, chained);
}

AdapterOutputs SlamAdapter::on_state(const kestrel::state_t& state) {
  AdapterOutputs out;
  if (!states_.empty() && state.utime <= states_.back().utime) {
    throw InputError(options_.state_channel + ": state " + std::to_string(state.utime) +
                     " is not newer than the previous one");
  }
  if (last_state_seq_ < 0 && map_loaded_) {
    // On a saved map every estimator is new to the map's world: like a restarted one, it gets
    // a correction at the first frame not older than its first state once the camera is placed
    // (the relocalising frame may come before the filter has started, which then drops it).
    restart_correction_due_ = true;
    restart_state_utime_ = state.utime;
  }
  if (last_state_seq_ >= 0 && state.seq < last_state_seq_) {
    // A new estimator (its seq starts again): its world is its own until SLAM's first
    // correction moves it onto the map's (estimator.h), so the map's world stays, the old
    // filter's states are no use for bridges, and the next frame its history holds (not older
    // than this state: it started before it) gets that correction.
    states_.clear();
    restart_correction_due_ = anchored_;
    restart_state_utime_ = state.utime;
    ++estimator_restarts_;
  }
  last_state_seq_ = state.seq;
  // DEGRADED is the IMU alone through a VO outage: what a bridge needs; anchoring wants OK.
  const bool ok = state.status == kestrel::state_t::STATUS_OK;
  if (!ok && state.status != kestrel::state_t::STATUS_DEGRADED) return out;
  StateSample sample;
  sample.utime = state.utime;
  // The map's world is fixed once: only by a state whose tilt is settled (a filter that started
  // on the move knows its roll and pitch to a few degrees at first, and a map anchored then
  // stays tilted against the filter's later world).
  // dtheta is in the body frame (state_t): roll and pitch are the world's x and y of it.
  sample.T_world_body = transport::from_message(state.T_world_body, options_.state_channel.c_str());
  double tilt_variance = 0.0;
  if (state.cov_dim >= 9 && static_cast<int>(state.covariance.size()) >= 9) {
    Eigen::Matrix3d rotation_body;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) rotation_body(r, c) = state.covariance[static_cast<size_t>(6 + r)][static_cast<size_t>(6 + c)];
    const Eigen::Matrix3d R = sample.T_world_body.linear();
    const Eigen::Matrix3d rotation_world = R * rotation_body * R.transpose();
    tilt_variance = std::max(rotation_world(0, 0), rotation_world(1, 1));
  }
  // The visual-only estimator (no gyro) is the exception: nothing re-measures its tilt after
  // its start (the accelerometer levels the start only, by default), so its world is the one
  // its first states show, however uncertain their tilt.
  const bool visual_only = state.filter == kestrel::state_t::FILTER_VISUAL_ONLY;
  if (!visual_only && std::isfinite(tilt_variance) && tilt_variance > 0.0) sample.tilt_sigma_rad = std::sqrt(tilt_variance);
  sample.ok = ok && std::isfinite(tilt_variance) &&
              (visual_only ||
               tilt_variance <= options_.anchor_max_tilt_sigma_rad * options_.anchor_max_tilt_sigma_rad);
  // The pose's covariance, which the graph inherits where it is anchored on this state.
  sample.pose_covariance = transport::pose_covariance_from(state);
  if (!sample.pose_covariance.allFinite()) sample.ok = false;  // not to anchor on; a bridge needs only the pose
  for (int i = 0; i < 3; ++i) {
    sample.velocity[i] = state.velocity[i];
    sample.angular_velocity[i] = state.angular_velocity[i];
  }
  if (!sample.velocity.allFinite() || !sample.angular_velocity.allFinite()) {
    throw InputError(options_.state_channel + ": state " + std::to_string(state.utime) + " has a non-finite velocity");
  }
  states_.push_back(sample);
  // A bridge spans a VO outage of a few seconds; older states are of no use.
  const auto keep_us = static_cast<int64_t>(std::llround(options_.max_bridge_s * 1e6)) + 1'000'000;
  while (states_.front().utime < state.utime - keep_us) states_.pop_front();
  try_anchor(out);
  return out;
}

std::optional<WorldAnchor> SlamAdapter::state_at(int64_t utime, bool ok_only) const {
  const auto after = std::lower_bound(states_.begin(), states_.end(), utime,
                                      [](const StateSample& s, int64_t t) { return s.utime < t; });
  if (after == states_.end()) {
    // Not reached yet (the IMU sample after a frame may come after it): carry the newest
    // state on by its velocities over at most a few IMU periods.
    if (states_.empty()) return std::nullopt;
    const StateSample& last = states_.back();
    const double dt = 1e-6 * static_cast<double>(utime - last.utime);
    if (dt > options_.max_state_extrapolation_s || (ok_only && !last.ok)) return std::nullopt;
    Eigen::Isometry3d T = last.T_world_body;
    T.translation() += dt * last.velocity;
    T.linear() = T.linear() * so3::exp(dt * last.angular_velocity);
    return WorldAnchor{T, last.pose_covariance};
  }
  if (after->utime == utime) {
    if (ok_only && !after->ok) return std::nullopt;
    return WorldAnchor{after->T_world_body, after->pose_covariance};
  }
  if (after == states_.begin()) return std::nullopt;  // the estimator started after it
  const auto before = std::prev(after);
  if (ok_only && !(before->ok && after->ok)) return std::nullopt;
  const double gap_s = 1e-6 * static_cast<double>(after->utime - before->utime);
  if (gap_s > options_.max_state_gap_s) return std::nullopt;
  const double fraction = 1e-6 * static_cast<double>(utime - before->utime) / gap_s;
  return WorldAnchor{se3::interpolate(before->T_world_body, after->T_world_body, fraction),
                     (1.0 - fraction) * before->pose_covariance + fraction * after->pose_covariance};
}

void SlamAdapter::remember(const FramePose& frame, bool reference) {
  if (anchored_) return;
  if (reference) recent_.clear();  // world_pose() composes from the newest reference on
  recent_.push_back(frame);
  while (static_cast<int>(recent_.size()) > options_.buffer_frames) recent_.pop_front();
}

void SlamAdapter::try_anchor(AdapterOutputs& out) {
  if (anchored_ || states_.empty() || slam_.keyframes().empty()) return;
  // The newest frame since the newest keyframe at which the estimator has an OK pose.
  for (auto f = recent_.rbegin(); f != recent_.rend(); ++f) {
    const auto state = state_at(f->utime, true);
    if (!state) continue;
    slam_.change_world(state->T_world_body * f->T_body_camera * slam_.world_pose(f->T_odom_camera).inverse());
    anchored_ = true;
    anchor_ = state;
    recent_.clear();
    out.anchored = true;
    out.graph = graph_message(slam_);
    return;
  }
}

AdapterOutputs SlamAdapter::process(const kestrel::rgbd_frame_t& message, const ChainedPose& waiting) {
  const OdometryPose& chained = waiting.pose;
  AdapterOutputs out;
  last_processed_utime_ = message.utime;
  const Eigen::Isometry3d T_body_camera =
      transport::from_message(message.camera.T_body_camera, options_.camera_channel.c_str());
  // The chain's poses, carried into SLAM's odometry frame past the bridged restarts.
  OdometryPose pose = chained;
  pose.T_odom_camera = odometry_fix_ * chained.T_odom_camera;
  OdometryLink link = OdometryLink::kContinuous;
  if (chained.broken || lost_break_) {
    link = OdometryLink::kBroken;
    // The VO restarted: the estimator's motion from the last frame with a pose to this one
    // (IMU through the outage) relates the new segment to the old one.
    if (last_pose_ && 1e-6 * static_cast<double>(message.utime - last_pose_->utime) <= options_.max_bridge_s) {
      const auto before = state_at(last_pose_->utime, false), now = state_at(message.utime, false);
      if (before && now) {
        const Eigen::Isometry3d T_before_now =
            (before->T_world_body * last_pose_->T_body_camera).inverse() * (now->T_world_body * T_body_camera);
        pose.T_odom_camera = last_pose_->T_odom_camera * T_before_now;
        odometry_fix_ = pose.T_odom_camera * chained.T_odom_camera.inverse();
        link = OdometryLink::kBridged;
        ++bridges_;
      }
    }
  }
  last_pose_ = FramePose{message.utime, pose.T_odom_camera, T_body_camera};
  if (!slam_.wants_keyframe(pose.T_odom_camera, link)) {
    remember(*last_pose_, false);
    try_anchor(out);
    correct_new_estimator(message.utime, waiting, link, out);
    return out;
  }
  const RgbdFrame frame = transport::decode_rgbd(message, options_.camera_channel.c_str());
  std::optional<Matrix6d> odometry_covariance;
  if (link == OdometryLink::kContinuous && reference_pose_) {
    odometry_covariance = chain_.relative_covariance(*reference_pose_, chained);
  }
  // The features' timing: the odometry's motion from the previous update (not across a restart).
  const sensors::SensorProfile& sensor = options_.sensor ? *options_.sensor : sensors::profile_of_sensor(frame.sensor);
  sensors::FrameMotion motion;
  if (link == OdometryLink::kContinuous && waiting.previous_utime != 0) {
    motion = keyframe_motion(vo::with_sensor(sensor, vo::VoOptions{}).depth, frame.utime, frame.depth_utime,
                             waiting.previous_utime, waiting.T_previous_current);
  }
  const SlamStep step = slam_.add(frame, pose.T_odom_camera, link, odometry_covariance, motion, sensor);
  const bool new_reference = step.new_reference();
  if (new_reference) reference_pose_ = chained;
  lost_break_ = false;
  remember(*last_pose_, new_reference);
  if (!new_reference) {
    try_anchor(out);
    return out;
  }
  level(step, message.utime, T_body_camera, out);
  // Placed in a saved map: the map's graph goes out too, so that the mapper (restored from its
  // journal) publishes the map the planner flies in before this flight makes a keyframe.
  // Not before: provisional keyframes (made before the placement) are in a frame of their own.
  // And after a loop closed without a keyframe (CoverageOptions::close_loops_in_place): the
  // keyframes moved.
  if ((step.keyframe || step.relocalised || step.loop_closed) && slam_.localized()) out.graph = graph_message(slam_);
  // Not placed yet: the keyframes waiting to join go out on their own, so that the mapper
  // keeps their frames until the placement brings them into the map.
  if (step.keyframe && !slam_.localized()) {
    kestrel::slam_graph_t unplaced = unplaced_graph_message(slam_);
    if (unplaced.num_keyframes > 0) out.unplaced = std::move(unplaced);
  }
  out.step = step;
  try_anchor(out);
  // A correction is a pose in the estimator's world: none before the graph is anchored in it
  // (in SLAM's odometry frame it would pull the state by the frames' difference). A frame
  // re-anchored on the map is located in it: that is a correction too.
  // Strictly after: the filter takes a correction only after its oldest state (estimator.cpp).
  // Never from a pose across an odometry break that no loop has placed yet: it assumes no motion
  // in the gap, and a new estimator would take it as the map's world whatever its error.
  // Not for a levelling alone: it turns the graph towards the estimator's own gravity, about
  // where the vehicle is, so the estimator's world is level already; a correction would only
  // pull the state to the odometry chain's position, which no loop has made better than its
  // own (stata, no loops: three levellings moved STATE 3-10 cm each, the wrong way;
  // docs/decisions/2026-12-06-stata-flights-rotation-drift.md).
  const bool new_estimator_waits =
      restart_correction_due_ && message.utime > restart_state_utime_ && slam_.odometry_placed();
  if ((step.optimisation || step.reanchored || step.relocalised || new_estimator_waits) && anchored_ &&
      slam_.localized()) {
    out.correction =
        correction_message(slam_, options_.correction_sigma_m, options_.correction_sigma_rad, std::nullopt, anchor_);
    if (new_estimator_waits) restart_correction_due_ = false;
  }
  return out;
}

bool SlamAdapter::level(const SlamStep& step, int64_t utime, const Eigen::Isometry3d& T_body_camera,
                        AdapterOutputs& out) {
  if (!step.keyframe || step.keyframe_id < 0) return false;
  // The estimator's up at this keyframe, in its camera frame: from a settled OK state with a
  // gravity-measured tilt (the sigma of the states state_at() takes). Any estimator's world is
  // level, so a restarted one's up is as good as the first's, and a camera-frame direction
  // needs no odometry (a keyframe after a break not yet placed is used once it is).
  {
    const auto after = std::lower_bound(states_.begin(), states_.end(), utime,
                                        [](const StateSample& s, int64_t t) { return s.utime < t; });
    double sigma = 0.0;
    if (after != states_.end() && after->utime == utime) {
      sigma = after->tilt_sigma_rad;
    } else if (after == states_.end()) {
      if (!states_.empty()) sigma = states_.back().tilt_sigma_rad;  // carried on from the newest
    } else if (after != states_.begin()) {
      const double before = std::prev(after)->tilt_sigma_rad;
      sigma = before > 0.0 && after->tilt_sigma_rad > 0.0 ? std::max(before, after->tilt_sigma_rad) : 0.0;
    }
    const auto state = sigma > 0.0 ? state_at(utime, true) : std::nullopt;
    if (state) {
      keyframe_up_[step.keyframe_id] =
          KeyframeUp{(state->T_world_body * T_body_camera).linear().transpose() * Eigen::Vector3d::UnitZ(), sigma};
    }
  }
  // Only a graph anchored here on the estimator's states: a saved map's world is fixed.
  if (!anchored_ || !anchor_ || !slam_.localized() || !slam_.odometry_placed() ||
      static_cast<int>(keyframe_up_.size()) < options_.level_min_keyframes)
    return false;
  const auto& poses = slam_.graph().poses;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weights = 0.0;
  int n = 0;
  for (const auto& [id, kf] : keyframe_up_) {
    if (id >= static_cast<int64_t>(poses.size())) continue;
    const double w = 1.0 / (kf.sigma_rad * kf.sigma_rad);
    sum += w * (poses[static_cast<size_t>(id)].linear() * kf.up_camera);
    weights += w;
    ++n;
  }
  if (n < options_.level_min_keyframes || !(sum.norm() > 0.0)) return false;
  const Eigen::Vector3d up = sum.normalized();
  const double sigma = std::sqrt(n / weights);  // root of the harmonic mean of the variances
  const double tilt = std::acos(std::clamp(up.z(), -1.0, 1.0));
  if (!(tilt > options_.level_min_tilt_rad && tilt > options_.level_sigmas * sigma)) return false;
  // No estimator's error tilts a map this far: a camera mounting that disagrees with the
  // frames (T_body_camera) would. Refused, and counted for the operator.
  if (tilt > options_.level_max_tilt_rad) {
    ++levels_refused_;
    return false;
  }
  // The smallest rotation taking the estimators' up to the graph's: about a horizontal axis,
  // so heading stays; about the newest keyframe, so where the vehicle is now stays.
  Eigen::Isometry3d T_level = Eigen::Isometry3d::Identity();
  T_level.linear() = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d pivot = poses[static_cast<size_t>(step.keyframe_id)].translation();
  T_level.translation() = pivot - T_level.linear() * pivot;
  slam_.change_world(T_level);
  // The anchoring state's pose turns with the graph: its covariance is carried about it
  // (correction_message's lever arm).
  anchor_->T_world_body = T_level * anchor_->T_world_body;
  Matrix6d turn = Matrix6d::Identity();  // dp is in the world, dtheta in the body (pose_t)
  turn.topLeftCorner<3, 3>() = T_level.linear();
  anchor_->covariance = turn * anchor_->covariance * turn.transpose();
  ++levellings_;
  out.levelled_rad = tilt;
  return true;
}

void SlamAdapter::correct_new_estimator(int64_t utime, const ChainedPose& chained, OdometryLink link,
                                        AdapterOutputs& out) {
  if (!restart_correction_due_ || !anchored_ || !slam_.localized() || !slam_.odometry_placed() ||
      utime <= restart_state_utime_)
    return;
  if (link != OdometryLink::kContinuous || !reference_pose_ || !last_pose_) return;
  const std::optional<Matrix6d> odometry = chain_.relative_covariance(*reference_pose_, chained.pose);
  if (!odometry) return;
  out.correction = correction_message(
      slam_, options_.correction_sigma_m, options_.correction_sigma_rad,
      FrameSinceKeyframe{utime, last_pose_->T_odom_camera, last_pose_->T_body_camera, *odometry}, anchor_);
  restart_correction_due_ = false;
}

}  // namespace kestrel::slam
