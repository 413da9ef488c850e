#include "ros/bridge.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <limits>
#include <map>
#include <optional>

#include <ros/callback_queue.h>
#include <ros/master.h>
#include <ros/ros.h>

#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "ros/ros_convert.h"
#include "ros/tf_tree.h"

namespace kestrel::ros1 {
namespace {

// A publisher per topic, advertised at its first message with that message's type (a topic
// kestrel never produces, e.g. no SLAM running, is never advertised), the state's at the start:
// a subscriber that connects before the first STATE misses none (roscpp keeps nothing for a
// subscriber still connecting).
class Publishers {
 public:
  explicit Publishers(ros::NodeHandle& nh) : nh_(nh) {}
  template <class Msg>
  void publish(const std::string& topic, const Msg& m, bool latched) {
    advertise<Msg>(topic, latched).publish(m);
  }
  template <class Msg>
  ros::Publisher& advertise(const std::string& topic, bool latched) {
    auto it = publishers_.find(topic);
    if (it == publishers_.end())
      it = publishers_.emplace(topic, nh_.advertise<Msg>(topic, latched ? 1 : 100, latched)).first;
    return it->second;
  }

 private:
  ros::NodeHandle& nh_;
  std::map<std::string, ros::Publisher> publishers_;
};

// One line per bad ROS message, at most one a second, and the count.
class RosRejections {
 public:
  void reject(const std::string& why) {
    ++count_;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_log_ < std::chrono::seconds(1)) return;
    last_log_ = now;
    spdlog::warn("dropped: {} ({} ROS messages dropped so far)", why, count_);
  }
  int64_t count() const { return count_; }

 private:
  int64_t count_ = 0;
  std::chrono::steady_clock::time_point last_log_{};
};

// A publisher of another type on a topic the bridge reads: roscpp refuses it connection by
// connection, in its own log, and the bridge would wait for frames that never come. The
// master's list of topics names the type: that is a stream that can give no frame.
void check_topic_types(const std::vector<ros::Subscriber>& subscribers, const std::vector<std::string>& types) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;  // the master is gone: the caller reports that
  for (const ros::master::TopicInfo& t : topics)
    for (size_t i = 0; i < subscribers.size(); ++i)
      if (t.name == subscribers[i].getTopic() && t.datatype != types[i])
        throw StreamError("ros-bridge: " + t.name + ": published as " + t.datatype + ", not " + types[i] +
                          " (another topic? see `rostopic list -v`)");
}

// How long the camera is silent before its waiting colour images are decided: several frame
// periods of a 30 Hz camera, far longer than a depth image arrives behind its colour image.
constexpr std::chrono::milliseconds kQuietCamera{250};

// The tf history kept per edge: a mount or a motion capture is looked up at the newest stamps.
constexpr int64_t kTfHistoryUs = 10'000'000;

}  // namespace

BridgeSummary run_bridge(const BridgeOptions& o) {
  // kestrel's Node handles SIGINT / SIGTERM; ROS's own handler would end ros::ok() instead.
  ros::init(ros::M_string{}, o.ros_name, ros::init_options::NoSigintHandler);
  if (!ros::master::check())
    throw UnavailableError("no ROS master at " + ros::master::getURI() +
                           " (start one with `roscore`, or set ROS_MASTER_URI to a running one)");

  transport::Node node("ros-bridge", o.lcm_url);  // UnavailableError: exit 4
  ros::NodeHandle nh;
  BridgeSummary summary;
  RosRejections rejections;
  std::optional<std::string> fatal;
  auto last_camera_message = std::chrono::steady_clock::now();

  // ROS -> LCM.
  TfTree tree(kTfHistoryUs);
  CameraStream camera(
      o.camera, "ros-bridge",
      [&](const std::string& channel, int64_t, const std::vector<uint8_t>& bytes) { node.publish_bytes(channel, bytes); },
      o.tf_topic.empty() ? nullptr : &tree, o.tf_topic);
  std::vector<ros::Subscriber> subscribers;
  std::vector<std::string> types;  // of each subscriber's messages
  // Each callback: a bad message is dropped and counted; a stream that cannot give a frame ends
  // the bridge (after the callback, from the loop).
  auto guarded = [&](auto handle) {
    return [&, handle](const auto& message) {
      if (fatal) return;
      last_camera_message = std::chrono::steady_clock::now();
      try {
        handle(*message);
      } catch (const StreamError& e) {
        fatal = e.what();
      } catch (const InputError& e) {
        rejections.reject(e.what());
      }
    };
  };
  if (!o.camera.colour_topic.empty()) {
    const auto hints = ros::TransportHints().tcpNoDelay();
    const auto& c = o.camera;
    subscribers.push_back(nh.subscribe<sensor_msgs::Image>(
        c.colour_topic, 30, guarded([&](const sensor_msgs::Image& m) { camera.colour(m); }), ros::VoidConstPtr(), hints));
    subscribers.push_back(nh.subscribe<sensor_msgs::Image>(
        c.depth_topic, 30, guarded([&](const sensor_msgs::Image& m) { camera.depth(m); }), ros::VoidConstPtr(), hints));
    if (!c.intrinsics)
      subscribers.push_back(nh.subscribe<sensor_msgs::CameraInfo>(
          c.camera_info_topic, 30, guarded([&](const sensor_msgs::CameraInfo& m) { camera.camera_info(m); }),
          ros::VoidConstPtr(), hints));
    if (!c.imu_topic.empty())
      subscribers.push_back(nh.subscribe<sensor_msgs::Imu>(
          c.imu_topic, 400, guarded([&](const sensor_msgs::Imu& m) { camera.imu(m); }), ros::VoidConstPtr(), hints));
    types = {ros::message_traits::DataType<sensor_msgs::Image>::value(),
             ros::message_traits::DataType<sensor_msgs::Image>::value()};
    if (!c.intrinsics) types.push_back(ros::message_traits::DataType<sensor_msgs::CameraInfo>::value());
    if (!c.imu_topic.empty()) types.push_back(ros::message_traits::DataType<sensor_msgs::Imu>::value());
    node.advertise(channel::kCameraRgbd);
    node.advertise(channel::kImu);
  }
  int64_t last_truth_utime = std::numeric_limits<int64_t>::min();
  summary.ground_truth = o.tf_topic.empty() ? "none: no tf read (--tf-topic \"\")" : "none: no transform on " + o.tf_topic;
  if (!o.tf_topic.empty()) {
    // The ground truth: the truth frame's pose in the truth world at each transform of the
    // chain's busiest edge, in stamp order. (The handlers below outlive this block: what they
    // hold by reference lives as long as the loop.)
    const std::string world = frame_name(o.mocap_world_frame), truth = frame_name(o.mocap_frame);
    const auto publish_truth = [&, world, truth](const std::vector<std::pair<std::string, int64_t>>& taken) {
      for (const TimedPose& p : tree.poses_at(taken, world, truth, o.tf_topic, summary.ground_truth)) {
        if (p.utime <= last_truth_utime) continue;  // in stamp order: a late one is dropped
        node.publish_bytes(channel::kGroundTruth, ground_truth_message(p.utime, p.T));
        last_truth_utime = p.utime;
        ++summary.ground_truth_poses;
      }
    };
    const std::string self = ros::this_node::getName();
    for (const bool is_static : {false, true}) {
      const std::string topic = o.tf_topic + (is_static ? "_static" : "");
      const boost::function<void(const ros::MessageEvent<tf2_msgs::TFMessage const>&)> on_tf =
          [&, self, topic, is_static, publish_truth](const ros::MessageEvent<tf2_msgs::TFMessage const>& event) {
            // Its own transforms (STATE's map -> base_link) are not the world's.
            if (fatal || event.getPublisherName() == self) return;
            try {
              const auto took = tree.add(*event.getConstMessage(), "ros-bridge: " + topic);
              summary.tf_transforms += static_cast<int64_t>(took.size());
              if (!is_static) publish_truth(took);
            } catch (const InputError& e) {
              rejections.reject(e.what());
            }
          };
      subscribers.push_back(nh.subscribe<tf2_msgs::TFMessage, const ros::MessageEvent<tf2_msgs::TFMessage const>&>(
          topic, is_static ? 10 : 100, on_tf));
      types.push_back(ros::message_traits::DataType<tf2_msgs::TFMessage>::value());
    }
    node.advertise(channel::kGroundTruth);
  }

  // LCM -> ROS: the Exporter, as bag-export uses it, publishing on topics.
  Publishers publishers(nh);
  RosSinkOf sink([&publishers](const std::string& topic, const ros::Time&, const auto& m, bool latched) {
    publishers.publish(topic, m, latched);
  });
  Exporter exporter(o.exporter, sink, summary.exported);
  if (o.to_ros) {
    publishers.advertise<nav_msgs::Odometry>(topic::kOdom, false);
    publishers.advertise<tf2_msgs::TFMessage>(topic::kTf, false);
    node.subscribe<kestrel::state_t>(channel::kState, [&](const kestrel::state_t& m) { exporter.state(m, "STATE"); }, 400);
    node.subscribe<kestrel::vo_update_t>(channel::kVoUpdate,
                                         [&](const kestrel::vo_update_t& m) { exporter.vo(m, "VO_UPDATE"); });
    node.subscribe<kestrel::slam_graph_t>(
        channel::kSlamGraph, [&](const kestrel::slam_graph_t& m) { exporter.graph(m, "SLAM_GRAPH"); }, 0);
    node.subscribe<kestrel::plan_t>(channel::kPlan, [&](const kestrel::plan_t& m) { exporter.plan(m, "PLAN"); });
    node.subscribe<kestrel::octomap_t>(
        channel::kMapOctomap, [&](const kestrel::octomap_t& m) { exporter.map(m, "MAP_OCTOMAP"); }, 2);
  }

  // A replay that restarts the system restarts the VO: its chain starts again here too.
  node.on_reset([&] { exporter.reset(); });
  node.set_health(kestrel::process_status_t::STATE_RUNNING, "");
  spdlog::info("bridging ROS master {} and LCM", ros::master::getURI());
  auto next_master_check = std::chrono::steady_clock::now();
  bool master_lost = false;
  ros::CallbackQueue& queue = *ros::getGlobalCallbackQueue();
  while (!fatal && node.spin_once(2)) {
    queue.callAvailable(ros::WallDuration(0.0));
    // A camera gone quiet (a bag played to its end): its last colour images wait for a depth
    // image after them that will not come; they take the nearest there is.
    if (camera.waiting() && std::chrono::steady_clock::now() - last_camera_message > kQuietCamera) camera.flush();
    if (const auto now = std::chrono::steady_clock::now(); now >= next_master_check) {
      next_master_check = now + std::chrono::milliseconds(static_cast<int64_t>(o.master_check_period_s * 1000));
      const bool lost = !ros::master::check();
      if (!lost) {
        try {
          check_topic_types(subscribers, types);
        } catch (const StreamError& e) {
          fatal = e.what();
        }
      }
      if (lost != master_lost) {
        master_lost = lost;
        if (lost) spdlog::warn("the ROS master at {} is not reachable; waiting for it", ros::master::getURI());
        node.set_health(lost ? kestrel::process_status_t::STATE_DEGRADED : kestrel::process_status_t::STATE_RUNNING,
                        lost ? "no ROS master at " + ros::master::getURI() : "");
      }
    }
  }
  summary.camera = camera.stats();
  summary.ros_messages_rejected = rejections.count();
  subscribers.clear();
  ros::shutdown();
  if (fatal) throw InputError(*fatal);
  return summary;
}

}  // namespace kestrel::ros1
