#pragma once
// kestrel's output messages (STATE, VO_UPDATE, GROUND_TRUTH, SLAM_GRAPH, PLAN, MAP_OCTOMAP,
// CAMERA_RGBD) as ROS 1 messages, handed to a RosSink: a bag (bag_export.h) or live ROS
// topics (ros-bridge). Both use this one Exporter, so a bag and the bridge carry the same
// messages on the same topics. See ros/README.md, "bag-export", for the topics and frames.
//
// Frames (REP-105 names, configurable): `world_frame` (default "map") is the estimator's world,
// the frame STATE's T_world_body is in (SLAM's world once the estimator took it); `body_frame`
// ("base_link") the vehicle body; `camera_frame` ("camera") the RGB camera's optical frame. The
// map -> odom -> base_link split of REP-105 waits for an odometry frame of kestrel's own
// (issue 39 item 1): today /tf holds map -> base_link directly.
//
// Every method throws InputError naming `what` for a message it cannot convert (a non-finite
// pose, a utime a ROS time cannot hold, a map that does not decode); nothing is written then.

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "ros/map_convert.h"
#include "tools/eval/vo_chain.h"

namespace kestrel::ros1 {

/// The topics the Exporter writes (ros/README.md, "bag-export").
namespace topic {
inline constexpr const char* kMapOccupied = "/kestrel/map/occupied";
inline constexpr const char* kMapFree = "/kestrel/map/free";
inline constexpr const char* kMapVoxels = "/kestrel/map/voxels";
inline constexpr const char* kOdom = "/kestrel/odom";
inline constexpr const char* kTf = "/tf";
inline constexpr const char* kVo = "/kestrel/vo";
inline constexpr const char* kGroundTruth = "/kestrel/ground_truth";
inline constexpr const char* kKeyframes = "/kestrel/slam/keyframes";
inline constexpr const char* kLoops = "/kestrel/slam/loops";
inline constexpr const char* kPlan = "/kestrel/plan";
inline constexpr const char* kColour = "/kestrel/camera/rgb/image_raw";
inline constexpr const char* kDepth = "/kestrel/camera/depth/image_raw";
inline constexpr const char* kCameraInfo = "/kestrel/camera/rgb/camera_info";
inline constexpr const char* kTfStatic = "/tf_static";
}  // namespace topic

struct ExportOptions {
  std::string world_frame = "map";
  std::string body_frame = "base_link";
  std::string camera_frame = "camera";
  /// VO_UPDATE's chained poses are the camera's in the VO's own world, the camera frame of the
  /// VO's first frame: /kestrel/vo's header.frame_id (not joined to the others by tf).
  std::string vo_frame = "vo";
  /// GROUND_TRUTH's world (the sim's, the motion capture's): /kestrel/ground_truth's frame_id.
  /// The estimator's world only where the run starts at the truth's pose (the sim does).
  std::string truth_frame = "map";
  /// CAMERA_RGBD as sensor_msgs/Image (colour rgb8, depth 16UC1 mm) and CameraInfo (big).
  bool images = false;
  /// MAP_OCTOMAP's free cells too, as /kestrel/map/free (many: every free cell's centre).
  bool map_free = false;
};

struct ExportStats {
  std::map<std::string, int64_t> messages;  ///< per topic, messages written
  int64_t log_events = 0;                   ///< events read from the log (bag-export)
  bool stopped = false;                     ///< `stopping` said so before the end (bag-export)
  int64_t vo_without_estimate = 0;          ///< VO_UPDATEs the chain gives no pose (VoChain)
  int64_t vo_out_of_order = 0;              ///< VO_UPDATEs not after the previous one, skipped
  std::string truth_of;                     ///< "body", "camera" or "" (no GROUND_TRUTH)
  int64_t total() const {
    int64_t n = 0;
    for (const auto& [topic, count] : messages) n += count;
    return n;
  }
};

/// Where the Exporter's messages go. `latched`: the message describes a state that a
/// subscriber joining later still needs (the camera's mount, the map, the plan, the graph); a
/// live publisher latches it, a bag ignores it.
class RosSink {
 public:
  virtual ~RosSink() = default;
  virtual void write(const std::string& topic, const ros::Time& t, const nav_msgs::Odometry& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const tf2_msgs::TFMessage& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const geometry_msgs::PoseStamped& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const nav_msgs::Path& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const sensor_msgs::Image& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const sensor_msgs::CameraInfo& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const sensor_msgs::PointCloud2& m, bool latched) = 0;
  virtual void write(const std::string& topic, const ros::Time& t, const visualization_msgs::MarkerArray& m,
                     bool latched) = 0;
};

/// A RosSink that hands every message to `f(topic, time, message, latched)`, a generic lambda.
template <class F>
class RosSinkOf final : public RosSink {
 public:
  explicit RosSinkOf(F f) : f_(std::move(f)) {}
  void write(const std::string& t, const ros::Time& s, const nav_msgs::Odometry& m, bool l) override { f_(t, s, m, l); }
  void write(const std::string& t, const ros::Time& s, const tf2_msgs::TFMessage& m, bool l) override { f_(t, s, m, l); }
  void write(const std::string& t, const ros::Time& s, const geometry_msgs::PoseStamped& m, bool l) override {
    f_(t, s, m, l);
  }
  void write(const std::string& t, const ros::Time& s, const nav_msgs::Path& m, bool l) override { f_(t, s, m, l); }
  void write(const std::string& t, const ros::Time& s, const sensor_msgs::Image& m, bool l) override { f_(t, s, m, l); }
  void write(const std::string& t, const ros::Time& s, const sensor_msgs::CameraInfo& m, bool l) override {
    f_(t, s, m, l);
  }
  void write(const std::string& t, const ros::Time& s, const sensor_msgs::PointCloud2& m, bool l) override {
    f_(t, s, m, l);
  }
  void write(const std::string& t, const ros::Time& s, const visualization_msgs::MarkerArray& m, bool l) override {
    f_(t, s, m, l);
  }

 private:
  F f_;
};

/// STATE as nav_msgs/Odometry: the pose of `body_frame` in `world_frame`, the twist in
/// `body_frame`'s axes, both covariances from state_t's error state (exporter.cpp says which
/// blocks go where). Throws InputError naming `what` for a non-finite pose.
nav_msgs::Odometry odometry_from_state(const kestrel::state_t& state, const std::string& world_frame,
                                       const std::string& body_frame, const std::string& what);

class Exporter {
 public:
  /// `sink` and `stats` are kept by reference.
  Exporter(ExportOptions options, RosSink& sink, ExportStats& stats);

  /// /kestrel/odom and /tf (world -> body).
  void state(const kestrel::state_t& s, const std::string& what);
  /// /kestrel/vo: the VO's motions chained by eval's VoChain; the camera's mount on /tf_static.
  void vo(const kestrel::vo_update_t& m, const std::string& what);
  /// /kestrel/ground_truth.
  void truth(const kestrel::ground_truth_t& m, const std::string& what);
  /// /kestrel/slam/keyframes: each revision's keyframes as a Path; /kestrel/slam/loops: its loop
  /// closures as line segments between keyframes.
  void graph(const kestrel::slam_graph_t& g, const std::string& what);
  /// /kestrel/plan.
  void plan(const kestrel::plan_t& m, const std::string& what);
  /// /kestrel/map/occupied (+ /kestrel/map/free with map_free) and /kestrel/map/voxels.
  void map(const kestrel::octomap_t& m, const std::string& what);
  /// The camera's mount on /tf_static (once); with `images`, the frame's images and CameraInfo.
  void camera(const kestrel::rgbd_frame_t& f, const std::string& what);

  /// Forgets the VO's chain and the camera's mount, as for a new run (lock-step replay's RESET):
  /// the VO's first frame after it starts a new chain instead of being out of order.
  void reset();

  const ExportOptions& options() const { return o_; }

 private:
  template <class Msg>
  void write(const std::string& topic, const ros::Time& t, const Msg& m, bool latched = false) {
    sink_.write(topic, t, m, latched);
    ++stats_.messages[topic];
  }
  void images(const kestrel::rgbd_frame_t& m, const std::string& what);
  void mount(const kestrel::pose3_t& T_body_camera, int64_t utime, const std::string& what);

  ExportOptions o_;
  RosSink& sink_;
  ExportStats& stats_;
  bool camera_written_ = false;
  eval::VoChain chain_;
  std::optional<int64_t> last_vo_utime_;
};

}  // namespace kestrel::ros1
