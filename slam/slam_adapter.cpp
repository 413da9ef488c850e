#include "slam/slam_adapter.h"

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::slam {

SlamAdapter::SlamAdapter(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary,
                         const AdapterOptions& adapter)
    : options_(adapter), slam_(options, std::move(vocabulary)) {
  if (adapter.buffer_frames < 1) throw std::invalid_argument("slam: buffer_frames must be >= 1");
}

void SlamAdapter::reset() {
  slam_.reset();
  chain_.reset();
  frames_.clear();
  poses_.clear();
  last_processed_utime_ = 0;
  lost_break_ = false;
  anchored_ = false;
  states_.clear();
  recent_.clear();
}

void SlamAdapter::trim_frames() {
  while (static_cast<int>(frames_.size()) > options_.buffer_frames) frames_.erase(frames_.begin());
}

void SlamAdapter::drop_poses(std::map<int64_t, OdometryPose>::iterator end) {
  for (auto it = poses_.begin(); it != end; ++it) lost_break_ |= it->second.broken;
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
  const OdometryPose p = pose->second;
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
  const auto frame = frames_.find(update.utime);
  if (frame == frames_.end()) {
    poses_[update.utime] = *pose;
    if (static_cast<int>(poses_.size()) > options_.buffer_frames) drop_poses(std::next(poses_.begin()));
    return {};
  }
  const kestrel::rgbd_frame_t message = std::move(frame->second);
  frames_.erase(frames_.begin(), std::next(frame));  // older frames will get no pose now
  return process(message, *pose);
}

AdapterOutputs SlamAdapter::on_state(const kestrel::state_t& state) {
  AdapterOutputs out;
  if (anchored_) return out;
  if (!states_.empty() && state.utime <= states_.back().first) {
    throw InputError(options_.state_channel + ": state " + std::to_string(state.utime) +
                     " is not newer than the previous one");
  }
  if (state.status != kestrel::state_t::STATUS_OK) return out;  // no trusted pose now
  const Eigen::Isometry3d T_world_body = transport::from_message(state.T_world_body, options_.state_channel.c_str());
  states_.emplace_back(state.utime, T_world_body);
  // Keyframes come at most a few seconds apart; older states can no longer bracket one.
  const int64_t keep_us = 10'000'000;
  while (states_.front().first < state.utime - keep_us) states_.pop_front();
  try_anchor(out);
  return out;
}

void SlamAdapter::remember(const kestrel::rgbd_frame_t& message, const OdometryPose& pose, bool keyframe) {
  if (anchored_) return;
  if (keyframe) recent_.clear();  // world_pose() composes from the newest keyframe on
  recent_.push_back({message.utime, pose.T_odom_camera,
                     transport::from_message(message.camera.T_body_camera, options_.camera_channel.c_str())});
  while (static_cast<int>(recent_.size()) > options_.buffer_frames) recent_.pop_front();
}

void SlamAdapter::try_anchor(AdapterOutputs& out) {
  if (anchored_ || states_.empty() || slam_.keyframes().empty()) return;
  // The newest frame since the newest keyframe that two states bracket.
  for (auto f = recent_.rbegin(); f != recent_.rend(); ++f) {
    const auto after = std::lower_bound(states_.begin(), states_.end(), f->utime,
                                        [](const auto& s, int64_t t) { return s.first < t; });
    if (after == states_.end()) continue;  // the estimator has not reached it yet
    const bool exact = after->first == f->utime;
    if (!exact && after == states_.begin()) break;  // the estimator started after it (and older ones)
    const auto before = exact ? after : std::prev(after);
    const double gap_s = 1e-6 * static_cast<double>(after->first - before->first);
    if (gap_s > options_.max_state_gap_s) continue;
    const double fraction = exact ? 0.0 : 1e-6 * static_cast<double>(f->utime - before->first) / gap_s;
    const Eigen::Isometry3d T_world_camera = se3::interpolate(before->second, after->second, fraction) * f->T_body_camera;
    slam_.change_world(T_world_camera * slam_.world_pose(f->T_odom_camera).inverse());
    anchored_ = true;
    states_.clear();
    recent_.clear();
    out.anchored = true;
    out.graph = graph_message(slam_);
    return;
  }
}

AdapterOutputs SlamAdapter::process(const kestrel::rgbd_frame_t& message, const OdometryPose& pose) {
  AdapterOutputs out;
  last_processed_utime_ = message.utime;
  const bool broken = pose.broken || lost_break_;
  if (!slam_.wants_keyframe(pose.T_odom_camera, broken)) {
    remember(message, pose, false);
    try_anchor(out);
    return out;
  }
  const RgbdFrame frame = transport::decode_rgbd(message, options_.camera_channel.c_str());
  const SlamStep step = slam_.add(frame, pose.T_odom_camera, broken);
  lost_break_ = false;
  remember(message, pose, step.keyframe);
  if (!step.keyframe) {
    try_anchor(out);
    return out;
  }
  out.graph = graph_message(slam_);
  if (step.optimisation) {
    out.correction = correction_message(slam_, options_.correction_sigma_m, options_.correction_sigma_rad);
  }
  out.step = step;
  try_anchor(out);
  return out;
}

}  // namespace kestrel::slam
