#pragma once
// The message side of kestrel-slam, without LCM: CAMERA_RGBD and VO_UPDATE messages in (in
// any interleaving), SLAM_GRAPH and SLAM_CORRECTION messages out. main.cpp wires it to a Node;
// tests feed it directly.
//
// World frame: SLAM's graph starts in the odometry frame (slam.h), which is not the state
// estimator's world (that one is gravity-aligned and fixed when the filter starts, maybe
// seconds after the first frame). SLAM_CORRECTION poses are applied by the estimator as poses
// in its own world, and the mapper's map must be in the frame the vehicle flies in, so the
// first frame since the newest keyframe that the estimator's STATE covers (an OK state on
// each side of its utime, at most max_state_gap_s apart) anchors the graph: the graph is moved
// rigidly so that this frame's pose (the newest keyframe's composed with the odometry since)
// is the estimator's pose then. A hovering vehicle makes no keyframe after the first, so any
// frame must do. Without STATE (offline runs) the world stays the odometry frame.
//
// A frame and its VO update are paired by utime. Frames wait (encoded) in a bounded buffer and
// are decoded only when their pose makes them a keyframe; an update whose frame has not come
// yet waits likewise. Invariants: at most `buffer_frames` frames and updates wait; a frame is
// given to SLAM at most once, in increasing utime.

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/state_t.hpp"
#include "slam/slam_messages.h"

namespace kestrel::slam {

struct AdapterOptions {
  int buffer_frames = 90;                 ///< frames (and updates) waiting for their partner
  double correction_sigma_m = 0.05;       ///< covariance of SLAM_CORRECTION (metres)
  double correction_sigma_rad = 0.02;     ///< and radians
  std::string camera_channel = "CAMERA_RGBD";  ///< named in error messages
  std::string vo_channel = "VO_UPDATE";
  std::string state_channel = "STATE";
  double max_state_gap_s = 0.1;           ///< STATE samples bracketing the anchoring keyframe
};

struct AdapterOutputs {
  std::optional<kestrel::slam_graph_t> graph;            ///< after a new keyframe or optimisation
  std::optional<kestrel::slam_correction_t> correction;  ///< after an optimisation
  std::optional<SlamStep> step;                          ///< what SLAM did (a keyframe was made)
  bool anchored = false;  ///< the graph was just moved into the estimator's world
};

class SlamAdapter {
 public:
  SlamAdapter(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary,
              const AdapterOptions& adapter = {});

  /// Throw InputError naming the channel for a message that cannot be used: the message is
  /// dropped (a corrupt keyframe is lost; the next frame that moved enough replaces it).
  AdapterOutputs on_frame(const kestrel::rgbd_frame_t& frame);
  AdapterOutputs on_vo_update(const kestrel::vo_update_t& update);
  /// The estimator's state: used only until the world is anchored. Throws InputError naming
  /// the channel for a pose that is not a rigid transform or a utime that goes back.
  AdapterOutputs on_state(const kestrel::state_t& state);
  void reset();

  /// True once the graph is in the estimator's world.
  bool anchored() const { return anchored_; }

  const Slam& slam() const { return slam_; }

 private:
  AdapterOutputs process(const kestrel::rgbd_frame_t& frame, const OdometryPose& pose);
  void trim_frames();
  /// Drops waiting poses [begin, end), remembering an odometry break among them.
  void drop_poses(std::map<int64_t, OdometryPose>::iterator end);
  /// Keeps a processed frame's poses for anchoring (frames since the newest keyframe).
  void remember(const kestrel::rgbd_frame_t& message, const OdometryPose& pose, bool keyframe);
  /// Anchors the graph at the newest remembered frame that STATE brackets; fills `out`.
  void try_anchor(AdapterOutputs& out);

  AdapterOptions options_;
  Slam slam_;
  OdometryChain chain_;
  std::map<int64_t, kestrel::rgbd_frame_t> frames_;  ///< utime -> waiting frame
  std::map<int64_t, OdometryPose> poses_;            ///< utime -> waiting pose
  int64_t last_processed_utime_ = 0;
  bool lost_break_ = false;  ///< a pose flagged broken was dropped: flag the next one
  bool anchored_ = false;
  std::deque<std::pair<int64_t, Eigen::Isometry3d>> states_;  ///< recent OK states, until anchored
  struct RecentFrame {
    int64_t utime;
    Eigen::Isometry3d T_odom_camera, T_body_camera;
  };
  std::deque<RecentFrame> recent_;  ///< frames since the newest keyframe, until anchored
};

}  // namespace kestrel::slam
