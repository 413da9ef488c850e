#pragma once
// The message side of kestrel-slam, without LCM: CAMERA_RGBD and VO_UPDATE messages in (in
// any interleaving), SLAM_GRAPH and SLAM_CORRECTION messages out (and SLAM_GRAPH_UNPLACED on a
// saved map before the placement). main.cpp wires it to a Node;
// tests feed it directly.
//
// World frame: SLAM's graph starts in the odometry frame (slam.h), which is not the state
// estimator's world (that one is gravity-aligned and fixed when the filter starts, maybe
// seconds after the first frame). SLAM_CORRECTION poses are applied by the estimator as poses
// in its own world, and the mapper's map must be in the frame the vehicle flies in, so the
// first frame since SLAM's newest reference (keyframe or re-anchored frame) that the estimator's STATE covers (an OK state with
// its roll and pitch settled, or a visual-only one, whose tilt nothing re-measures, on each
// side of its utime, at most max_state_gap_s apart, or the
// newest carried on by its velocities for up to max_state_extrapolation_s) anchors the graph: the graph is moved
// rigidly so that this frame's pose (the reference's composed with the odometry since)
// is the estimator's pose then. A hovering vehicle makes no keyframe after the first, so any
// frame must do. Without STATE (offline runs) the world stays the odometry frame, and no
// SLAM_CORRECTION is published until the graph is anchored: the estimator applies one as a
// pose in its own world.
//
// A saved map (kestrel-slam --map): its world is the world from the start; nothing is
// anchored, and the frame that relocalises the camera in it sends the first SLAM_CORRECTION.
// The estimator is new to that world, as a restarted one (below): once the camera is placed,
// the first frame not older than its first state gets a correction too.
//
// Estimator restarts: a restarted estimator (its STATE seq starts again) begins a world of its
// own; SLAM keeps the map's, drops the old filter's states, and sends a SLAM_CORRECTION for the
// next frame it processes that is not older than the new filter's first state (the pose of
// SLAM's reference composed with the odometry since, Slam::world_pose), which the new
// filter takes as the map's world (estimator.h) without waiting for a loop closure, nor for a
// keyframe, which a hovering vehicle never makes. Where the odometry since the keyframe has
// no covariance (the VO restarted since), the correction waits for the next keyframe; where
// the VO restarted and nothing bridged it (Slam::odometry_placed()), for the loop closure that
// places the new odometry in the map, never going out from a pose that assumes no motion.
//
// VO restarts: when the visual odometry loses its reference (a blank wall, a fast turn) its
// new segment is unrelated to the old one, and the heading turned in the gap would be lost for
// good. The estimator carries on through the gap on the IMU, so its motion from the last frame
// that had a pose to the first frame of the new segment (STATE interpolated, OK or DEGRADED,
// at most max_bridge_s apart) bridges it: later poses are carried on from there and the
// keyframe's odometry edge gets the bridge's uncertainty (OdometryLink::kBridged). Without
// states around both frames the restart stays a break, as before.
//
// Levelling: the graph's tilt is the anchoring state's, and a filter's roll and pitch can be a
// degree off when it anchors (started on the move, its tilt still settling) while the gravity
// it keeps measuring puts them right later; a rigid map tilted by 1.5 degrees is 0.4 m too high
// 17 m away, out of a planner's height band. So, once anchored on the estimator's states (not
// on a saved map, whose world is fixed), each keyframe keeps the world's up as the estimator
// had it then (a state with a gravity-measured tilt and its sigma: not the visual-only
// filter's); when their 1/sigma^2-weighted mean, in the graph's current frame, is tilted from
// the graph's up by more than level_min_tilt_rad and level_sigmas of sqrt(n / sum sigma^-2)
// (the sigma of one typical sample, not of the mean: a filter's tilt errors last for seconds,
// so neighbouring keyframes do not measure them independently), the graph is turned rigidly
// about the newest keyframe by the smallest rotation that levels it (heading and that
// keyframe's position unchanged), the anchoring state with it, and a SLAM_GRAPH goes out. No
// SLAM_CORRECTION: the estimator's world is level already, and the correction would only pull
// its state to the odometry chain's position. Known limit: an overconfident filter's early
// ups weigh as much as later ones (docs/decisions/2026-12-06-slam-levelling.md).
//
// A frame and its VO update are paired by utime. Frames wait (encoded) in a bounded buffer and
// are decoded only when their pose makes them a keyframe; an update whose frame has not come
// yet waits likewise.
//
// Timing: a keyframe's features get the odometry's timing correction (place/frame_features.h)
// with the camera's timing (the VO's DepthOptions of the sensor profile: `sensor` if set, else
// the one the frame's sensor model names; the simulator's corrects nothing) and the motion the
// chained VO_UPDATEs give from the frame before the keyframe (the previous update, whether or
// not its frame came) to it.
// Invariants: at most `buffer_frames` frames and updates wait; a frame is
// given to SLAM at most once, in increasing utime.

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/state_t.hpp"
#include "slam/slam_messages.h"
#include "vo/options.h"
#include "sensors/sensor_profile.h"
#include "vo/sensor_profile.h"

namespace kestrel::slam {

struct AdapterOptions {
  int buffer_frames = 90;                 ///< frames (and updates) waiting for their partner
  double correction_sigma_m = 0.05;       ///< covariance of SLAM_CORRECTION (metres)
  double correction_sigma_rad = 0.02;     ///< and radians
  std::string camera_channel = "CAMERA_RGBD";  ///< named in error messages
  std::string vo_channel = "VO_UPDATE";
  std::string state_channel = "STATE";
  double max_state_gap_s = 0.1;           ///< STATE samples bracketing a frame at most this far apart
  double anchor_max_tilt_sigma_rad = 0.01;  ///< anchor only on a STATE whose roll/pitch sigma is below this
  double max_state_extrapolation_s = 0.02;  ///< a frame after the newest STATE: carried on by its velocities
  double max_bridge_s = 10.0;             ///< longest VO outage the estimator's motion may bridge
  // Levelling (above): a tilt of the graph is corrected when it exceeds both bounds, once at
  // least level_min_keyframes keyframes have the estimator's up.
  double level_min_tilt_rad = 0.005;
  double level_sigmas = 3.0;
  int level_min_keyframes = 5;
  double level_max_tilt_rad = 0.1;  ///< a larger tilt is refused (levels_refused()), not corrected
  /// The camera's profile, whose timing (depth offset, rolling shutter) the keyframes'
  /// features are corrected with as the VO corrects them (kestrel-slam --sensor); unset: each
  /// frame's sensor model names it (sensors::profile_of_sensor).
  std::optional<sensors::SensorProfile> sensor;
};

struct AdapterOutputs {
  std::optional<kestrel::slam_graph_t> graph;            ///< after a new keyframe or optimisation
  /// On a saved map, after a keyframe made before the camera is placed: those keyframes
  /// (unplaced_graph_message), for SLAM_GRAPH_UNPLACED.
  std::optional<kestrel::slam_graph_t> unplaced;
  std::optional<kestrel::slam_correction_t> correction;  ///< after an optimisation or a re-anchoring, or for a new estimator
  std::optional<SlamStep> step;                          ///< what SLAM did (a keyframe was made or a frame re-anchored)
  bool anchored = false;  ///< the graph was just moved into the estimator's world
  double levelled_rad = 0.0;  ///< the graph was just turned level by this angle (0: not)
};

class SlamAdapter {
 public:
  SlamAdapter(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary,
              const AdapterOptions& adapter = {});
  /// Goes on from a saved map (Slam's constructor from a map): the map's world is the world
  /// from the start (nothing is anchored on STATE), and the frame that relocalises the camera
  /// in it sends a SLAM_CORRECTION, which an estimator told to await the map's world takes
  /// as its world (estimator.h, --await-world).
  SlamAdapter(std::shared_ptr<const SlamMap> map, const SlamOptions& options, const AdapterOptions& adapter = {});

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
  /// VO restarts bridged by the estimator's motion so far.
  int bridges() const { return bridges_; }
  /// New estimators seen on STATE (its seq started again): a restarted process.
  int estimator_restarts() const { return estimator_restarts_; }
  /// Times the graph was turned level (levelling, above), and tilts beyond level_max_tilt_rad
  /// that were not.
  int levellings() const { return levellings_; }
  int levels_refused() const { return levels_refused_; }

  const Slam& slam() const { return slam_; }

 private:
  struct FramePose {  ///< a processed frame in SLAM's odometry frame, and its camera mounting
    int64_t utime;
    Eigen::Isometry3d T_odom_camera, T_body_camera;
  };
  struct ChainedPose {  ///< a VO_UPDATE chained, and the motion from the update before it
    OdometryPose pose;
    int64_t previous_utime = 0;  ///< 0: none (the first, or after a restart)
    Eigen::Isometry3d T_previous_current = Eigen::Isometry3d::Identity();
  };
  AdapterOutputs process(const kestrel::rgbd_frame_t& frame, const ChainedPose& chained);
  /// The estimator's T_world_body at utime and its covariance (pose_t's convention):
  /// interpolated between two states, or carried on from the newest by its velocities (the
  /// covariance the newest's); nothing when the states do not cover it.
  std::optional<WorldAnchor> state_at(int64_t utime, bool ok_only) const;
  void trim_frames();
  /// Drops waiting poses [begin, end), remembering an odometry break among them.
  void drop_poses(std::map<int64_t, ChainedPose>::iterator end);
  /// Keeps a processed frame for anchoring (frames since SLAM's newest reference).
  void remember(const FramePose& frame, bool reference);
  /// Anchors the graph at the newest remembered frame that STATE brackets; fills `out`.
  void try_anchor(AdapterOutputs& out);
  /// The correction a new estimator waits for, at the frame just processed (not a keyframe;
  /// last_pose_), when it may be sent there; fills `out`.
  void correct_new_estimator(int64_t utime, const ChainedPose& chained, OdometryLink link, AdapterOutputs& out);
  /// Keeps the estimator's up at the new keyframe and levels the graph when it is due
  /// (levelling, above); true when it turned the graph.
  bool level(const SlamStep& step, int64_t utime, const Eigen::Isometry3d& T_body_camera, AdapterOutputs& out);

  AdapterOptions options_;
  Slam slam_;
  bool map_loaded_ = false;  ///< started from a saved map with keyframes: its world is the world
  OdometryChain chain_;
  std::map<int64_t, kestrel::rgbd_frame_t> frames_;  ///< utime -> waiting frame
  std::map<int64_t, ChainedPose> poses_;             ///< utime -> waiting pose
  std::optional<OdometryPose> previous_chained_;     ///< the chain's newest pose
  int64_t last_processed_utime_ = 0;
  bool lost_break_ = false;  ///< a pose flagged broken was dropped: flag the next one
  bool anchored_ = false;
  std::optional<WorldAnchor> anchor_;  ///< the state the graph was anchored on (none on a saved map)
  struct StateSample {
    int64_t utime = 0;
    bool ok = false;  ///< status OK and the tilt settled: fit to anchor on (else only to bridge)
    double tilt_sigma_rad = 0.0;  ///< of roll and pitch, measured by gravity (IMU filters); 0: unknown
    Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
    Matrix6d pose_covariance = Matrix6d::Zero();                 ///< pose_t's convention; zero if STATE has none
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          ///< world
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< body
  };
  std::deque<StateSample> states_;  ///< the last max_bridge_s (+1 s) of states
  std::optional<FramePose> last_pose_;  ///< the last processed frame
  std::optional<OdometryPose> reference_pose_;  ///< the chain's pose of SLAM's reference (Slam::reference())
  Eigen::Isometry3d odometry_fix_ = Eigen::Isometry3d::Identity();  ///< chain -> SLAM's odometry frame
  int bridges_ = 0;
  int64_t last_state_seq_ = -1;
  bool restart_correction_due_ = false;  ///< a new estimator waits for the map's world
  int64_t restart_state_utime_ = 0;      ///< the new estimator's first state
  int estimator_restarts_ = 0;
  std::deque<FramePose> recent_;  ///< frames since the newest reference, until anchored
  struct KeyframeUp {  ///< the world's up as the estimator had it at a keyframe
    Eigen::Vector3d up_camera;  ///< unit, in the keyframe's camera frame
    double sigma_rad;           ///< the state's tilt sigma
  };
  std::map<int64_t, KeyframeUp> keyframe_up_;  ///< keyframe index -> the estimator's up there
  int levellings_ = 0;
  int levels_refused_ = 0;
};

}  // namespace kestrel::slam
