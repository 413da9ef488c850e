#include "ros/bag_import.h"

#include <algorithm>
#include <map>
#include <utility>

#include <boost/make_shared.hpp>
#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include "common/error.h"
#include "common/time.h"
#include "common/transport/channels.h"
#include "drivers/tum/association.h"
#include "ros/camera_source.h"
#include "ros/legacy_camera_info.h"
#include "ros/ros_convert.h"
#include "ros/tf_tree.h"

namespace kestrel::ros1 {
namespace {

// "/camera/depth/image at 1305031104.659863 s", for an error about one message.
std::string at(const std::string& topic, const ros::Time& stamp) {
  return topic + " at " + format_seconds(to_utime(stamp)) + " s";
}

// The topics of the bag with their message types, for checks and error messages.
struct Topics {
  std::map<std::string, const rosbag::ConnectionInfo*> by_name;

  bool has(const std::string& topic) const { return !topic.empty() && by_name.count(topic) > 0; }
  std::string list() const {
    std::string s;
    for (const auto& [name, c] : by_name) s += (s.empty() ? "" : ", ") + name + " (" + c->datatype + ")";
    return s.empty() ? "none" : s;
  }
  // Throws unless `topic` carries messages of type T (by MD5, as librosbag's instantiate does:
  // tf/tfMessage of older bags and tf2_msgs/TFMessage are the same definition).
  template <class T>
  void require_type(const std::string& bag, const std::string& topic, const std::string& hint = "") const {
    const rosbag::ConnectionInfo* c = by_name.at(topic);
    const std::string expected = ros::message_traits::DataType<T>::value();
    if (c->md5sum != ros::message_traits::MD5Sum<T>::value()) {
      throw InputError(bag + ": " + topic + ": messages are " + c->datatype + " (md5 " + c->md5sum + "), not " +
                       expected + (c->datatype == expected ? " as this ROS defines it (another definition)" : "") +
                       hint);
    }
  }
};

// The message as T. A message cut shorter than its type (the deserialiser's overrun) is an
// error naming the topic, not a bare "Buffer Overrun"; one of another type (a bag file may hold
// several connections on one topic, and only the first was checked; neither librosbag's nor
// python3-rosbag's writer makes such a file) is an error, not a null pointer.
template <class T>
boost::shared_ptr<T> read_as(const rosbag::MessageInstance& m, const std::string& path) {
  const std::string where = path + ": " + m.getTopic() + " at " + format_seconds(to_utime(m.getTime())) + " s (bag time)";
  boost::shared_ptr<T> message;
  try {
    message = m.instantiate<T>();
  } catch (const ros::serialization::StreamOverrunException&) {
    throw InputError(where + ": a " + m.getDataType() + " message shorter than its type says (cut or damaged)");
  }
  if (!message)
    throw InputError(where + ": a " + m.getDataType() + " message (md5 " + m.getMD5Sum() + ") among " +
                     ros::message_traits::DataType<T>::value() + " ones");
  return message;
}

// The stamps of one image topic sorted, repeated stamps dropped (counted): an image is known
// by its stamp in both passes, whatever order librosbag gives them in.
std::vector<int64_t> sorted_unique(std::vector<int64_t> stamps, size_t& repeated) {
  std::sort(stamps.begin(), stamps.end());
  const auto end = std::unique(stamps.begin(), stamps.end());
  repeated += static_cast<size_t>(stamps.end() - end);
  stamps.erase(end, stamps.end());
  return stamps;
}

enum class Kind { kImu = 0, kGroundTruth = 1, kFrame = 2 };
struct Event {
  int64_t utime = 0;
  Kind kind = Kind::kFrame;
  size_t index = 0;  // into the pairs, imu or poses
};

BagImportStats import(rosbag::Bag& bag, const std::string& path, const BagImportOptions& o, const ImportSink& sink) {
  BagImportStats stats;
  Topics topics;
  rosbag::View everything(bag);
  for (const rosbag::ConnectionInfo* c : everything.getConnections()) topics.by_name.emplace(c->topic, c);

  for (const std::string* t : {&o.colour_topic, &o.depth_topic}) {
    if (!topics.has(*t))
      throw InputError(path + ": " + *t + ": no such topic (" + (t == &o.colour_topic ? "colour" : "depth") +
                       " images; the bag has: " + topics.list() + ")");
    topics.require_type<sensor_msgs::Image>(path, *t);
  }

  // First pass: stamps, checks, calibration, IMU and poses; no pixels kept.
  std::string colour_frame;  // the colour images' frame_id: the camera's optical frame, the body
  auto stamps_of = [&](const std::string& topic, bool depth, int& width, int& height) {
    std::vector<int64_t> stamps;
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      if (sink.stopping()) return stamps;
      const auto image = read_as<sensor_msgs::Image>(m, path);
      const std::string what = path + ": " + at(topic, image->header.stamp);
      check_image(*image, depth, what);
      if (stamps.empty()) {
        if (!depth) colour_frame = frame_name(image->header.frame_id);
        width = static_cast<int>(image->width);
        height = static_cast<int>(image->height);
      } else if (width != static_cast<int>(image->width) || height != static_cast<int>(image->height)) {
        throw InputError(what + ": image is " + std::to_string(image->width) + "x" + std::to_string(image->height) +
                         ", the topic's first was " + std::to_string(width) + "x" + std::to_string(height));
      }
      stamps.push_back(to_utime(image->header.stamp));
    }
    return stamps;
  };
  int colour_w = 0, colour_h = 0, depth_w = 0, depth_h = 0;
  const std::vector<int64_t> colour_by_order = stamps_of(o.colour_topic, false, colour_w, colour_h);
  const std::vector<int64_t> depth_by_order = stamps_of(o.depth_topic, true, depth_w, depth_h);
  if (sink.stopping()) {
    stats.stopped = true;
    return stats;
  }
  check_depth_size(colour_w, colour_h, depth_w, depth_h, o, path);

  if (o.intrinsics) {
    stats.camera = intrinsics_camera(*o.intrinsics, colour_w, colour_h);
  } else {
    if (!topics.has(o.camera_info_topic))
      throw InputError(path + ": " + o.camera_info_topic + ": no such topic (the colour camera's CameraInfo; give "
                       "--camera-info-topic, or --intrinsics; the bag has: " + topics.list() + ")");
    // Today's definition, or the one before ROS Electric that TUM's 2011 bags may hold.
    const rosbag::ConnectionInfo* connection = topics.by_name.at(o.camera_info_topic);
    const bool old_definition = connection->md5sum != ros::message_traits::MD5Sum<sensor_msgs::CameraInfo>::value() &&
                                legacy::is_pre_electric_camera_info(connection->msg_def);
    if (!old_definition) topics.require_type<sensor_msgs::CameraInfo>(path, o.camera_info_topic, "; give --intrinsics");
    rosbag::View view(bag, rosbag::TopicQuery(o.camera_info_topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto info = old_definition ? boost::make_shared<sensor_msgs::CameraInfo>(
                                             legacy::to_current(*read_as<legacy::CameraInfo>(m, path)))
                                       : read_as<sensor_msgs::CameraInfo>(m, path);
      const PinholeCamera c = camera_from_info(*info, path + ": " + at(o.camera_info_topic, info->header.stamp));
      if (stats.camera_infos++ == 0) {
        stats.camera = c;
      } else if (!same_camera(c, stats.camera)) {
        ++stats.camera_info_changes;
      }
    }
    if (stats.camera_infos == 0) throw InputError(path + ": " + o.camera_info_topic + ": no CameraInfo message");
    check_camera_size(stats.camera, colour_w, colour_h, o, path);
  }

  std::vector<ImuReading> imu;
  std::string imu_frame;
  if (topics.has(o.imu_topic)) {
    topics.require_type<sensor_msgs::Imu>(path, o.imu_topic);
    rosbag::View view(bag, rosbag::TopicQuery(o.imu_topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = read_as<sensor_msgs::Imu>(m, path);
      ImuReading r = imu_from_message(*msg, path + ": " + at(o.imu_topic, msg->header.stamp));
      if (imu.empty() && stats.imu_empty == 0) imu_frame = frame_name(msg->header.frame_id);
      if (!r.has_gyro && !r.has_accel) {
        ++stats.imu_empty;
        continue;
      }
      imu.push_back(r);
    }
    std::stable_sort(imu.begin(), imu.end(), [](const ImuReading& a, const ImuReading& b) { return a.utime < b.utime; });
  }

  // The tf tree (for the ground truth and the IMU's axes).
  TfTree tree;
  const bool have_tf = !o.tf_topic.empty() && (topics.has(o.tf_topic) || topics.has(o.tf_topic + "_static"));
  if (have_tf) {
    for (const std::string& topic : {o.tf_topic, o.tf_topic + "_static"}) {
      if (!topics.has(topic)) continue;
      topics.require_type<tf2_msgs::TFMessage>(path, topic);
      rosbag::View view(bag, rosbag::TopicQuery(topic));
      for (const rosbag::MessageInstance& m : view) tree.add(*read_as<tf2_msgs::TFMessage>(m, path), path + ": " + topic);
    }
  }

  // The IMU in the body's axes (the camera's optical frame): rotated by the tf tree's mount when
  // its frame is another one the tree joins to the camera's; the lever arm is not modelled.
  stats.imu_axes = "as published";
  if (!imu.empty() && !colour_frame.empty()) {
    const ImuAxes axes =
        imu_axes(tree, imu_frame, colour_frame, imu.front().utime, have_tf ? o.tf_topic : "tf (no tf topic)");
    if (axes.R_camera_imu)
      for (ImuReading& r : imu) {
        r.angular_velocity = *axes.R_camera_imu * r.angular_velocity;
        r.linear_acceleration = *axes.R_camera_imu * r.linear_acceleration;
      }
    stats.imu_axes = axes.description;
  }

  std::vector<TimedPose> poses;
  if (!o.pose_topic.empty()) {
    if (!topics.has(o.pose_topic)) throw InputError(path + ": " + o.pose_topic + ": no such topic (ground-truth poses; the bag has: " + topics.list() + ")");
    topics.require_type<geometry_msgs::PoseStamped>(path, o.pose_topic);
    rosbag::View view(bag, rosbag::TopicQuery(o.pose_topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = read_as<geometry_msgs::PoseStamped>(m, path);
      poses.push_back({to_utime(msg->header.stamp), to_isometry(msg->pose, path + ": " + at(o.pose_topic, msg->header.stamp))});
    }
    std::stable_sort(poses.begin(), poses.end(), [](const TimedPose& a, const TimedPose& b) { return a.utime < b.utime; });
    stats.ground_truth = o.pose_topic + " (geometry_msgs/PoseStamped)";
  } else if (have_tf) {
    poses = tree.poses(frame_name(o.world_frame), frame_name(o.camera_frame), o.tf_topic, stats.ground_truth);
  } else {
    stats.ground_truth = o.tf_topic.empty() ? "none: no tf topic given" : "none: no " + o.tf_topic + " topic";
  }

  // Pairing: the TUM reader's rule and code.
  const std::vector<int64_t> colour_times = sorted_unique(colour_by_order, stats.repeated_stamps);
  const std::vector<int64_t> depth_times = sorted_unique(depth_by_order, stats.repeated_stamps);
  const tum::Association association = tum::associate(colour_times, depth_times, o.max_difference_us);
  stats.colour_images = colour_times.size();
  stats.depth_images = depth_times.size();
  stats.unmatched_colour = association.unmatched_a;
  stats.unused_depth = association.unused_b;
  stats.shared_depth = association.shared_b;
  if (association.pairs.empty()) {
    const auto span = [](const std::vector<int64_t>& t) {
      return t.empty() ? std::string("none")
                       : std::to_string(t.size()) + " from " + format_seconds(t.front()) + " to " + format_seconds(t.back()) + " s";
    };
    throw InputError(path + ": no image on " + o.colour_topic + " has one on " + o.depth_topic + " within " +
                     format_seconds(o.max_difference_us) + " s (colour: " + span(colour_times) + "; depth: " +
                     span(depth_times) + ")");
  }

  // What the second pass keeps, by stamp: the pair of each colour image that makes a frame,
  // and each depth image's index and how many frames it still serves.
  std::map<int64_t, size_t> pair_of_colour, index_of_depth;
  std::vector<int> depth_users(depth_times.size(), 0);
  for (size_t p = 0; p < association.pairs.size(); ++p) {
    pair_of_colour.emplace(colour_times[association.pairs[p].a], p);
    ++depth_users[association.pairs[p].b];
  }
  for (size_t d = 0; d < depth_times.size(); ++d)
    if (depth_users[d] > 0) index_of_depth.emplace(depth_times[d], d);

  std::vector<Event> events;
  events.reserve(association.pairs.size() + imu.size() + poses.size());
  for (size_t p = 0; p < association.pairs.size(); ++p) events.push_back({colour_times[association.pairs[p].a], Kind::kFrame, p});
  for (size_t i = 0; i < imu.size(); ++i) events.push_back({imu[i].utime, Kind::kImu, i});
  for (size_t i = 0; i < poses.size(); ++i) events.push_back({poses[i].utime, Kind::kGroundTruth, i});
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    return a.utime != b.utime ? a.utime < b.utime : a.kind < b.kind;
  });

  // Second pass: pixels, written in event order as soon as a frame's two images are read.
  std::map<size_t, cv::Mat> colour_ready;  // by pair
  std::map<size_t, cv::Mat> depth_ready;   // by depth index
  size_t next = 0;
  int64_t imu_seq = 0;
  auto flush = [&] {
    for (; next < events.size(); ++next) {
      const Event& e = events[next];
      if (e.kind == Kind::kImu) {
        const ImuReading& r = imu[e.index];
        sink.publish(channel::kImu, r.utime, imu_message(r, imu_seq++));
        ++stats.imu_samples;
        continue;
      }
      if (e.kind == Kind::kGroundTruth) {
        sink.publish(channel::kGroundTruth, poses[e.index].utime, ground_truth_message(poses[e.index].utime, poses[e.index].T));
        ++stats.ground_truth_poses;
        continue;
      }
      const tum::AssociatedPair& p = association.pairs[e.index];
      const auto c = colour_ready.find(e.index);
      const auto d = depth_ready.find(p.b);
      if (c == colour_ready.end() || d == depth_ready.end()) return;  // not read yet
      const int64_t colour_utime = colour_times[p.a];
      sink.publish(channel::kCameraRgbd, colour_utime,
                   frame_message(colour_utime, depth_times[p.b], static_cast<int64_t>(p.a), stats.camera, c->second,
                                 d->second, o));
      ++stats.frames;
      colour_ready.erase(c);
      pair_of_colour.erase(colour_utime);  // a repeated stamp later is not read again
      if (--depth_users[p.b] == 0) depth_ready.erase(d);
    }
  };
  rosbag::View images(bag, rosbag::TopicQuery(std::vector<std::string>{o.colour_topic, o.depth_topic}));
  for (const rosbag::MessageInstance& m : images) {
    if (sink.stopping()) {
      stats.stopped = true;
      return stats;
    }
    const bool is_colour = m.getTopic() == o.colour_topic;
    const auto image = read_as<sensor_msgs::Image>(m, path);
    const int64_t utime = to_utime(image->header.stamp);
    const std::string what = path + ": " + at(m.getTopic(), image->header.stamp);
    if (is_colour) {
      const auto it = pair_of_colour.find(utime);
      // Not a frame's, or a repeated stamp whose first image is read already.
      if (it == pair_of_colour.end() || colour_ready.count(it->second)) continue;
      colour_ready[it->second] = colour_to_rgb(*image, what);
    } else {
      const auto it = index_of_depth.find(utime);
      if (it == index_of_depth.end() || depth_users[it->second] == 0 || depth_ready.count(it->second)) continue;
      depth_ready[it->second] = depth_to_mm(*image, what);
    }
    flush();
  }
  flush();
  if (next != events.size())  // the bag changed between the passes, or librosbag skipped a message
    throw InputError(path + ": the second reading of the images did not find every image the first found");
  return stats;
}

}  // namespace

BagImportStats import_bag(const std::string& bag_path, const BagImportOptions& options, const ImportSink& sink) {
  try {
    rosbag::Bag bag;
    bag.open(bag_path, rosbag::bagmode::Read);
    return import(bag, bag_path, options, sink);
  } catch (const rosbag::BagUnindexedException& e) {
    throw InputError(bag_path + ": the bag has no index (truncated, or its recording was cut short; `rosbag "
                     "reindex` may recover it): " + e.what());
  } catch (const rosbag::BagIOException& e) {
    // A read past the end: the file was cut (a copy or a recording that stopped), or its
    // records are damaged; librosbag's own words say how far it got.
    throw InputError(bag_path + ": cannot read the bag: it ends early or is damaged (librosbag: " + e.what() + ")");
  } catch (const rosbag::BagFormatException& e) {
    throw InputError(bag_path + ": not a ROS 1 bag, or a damaged one (librosbag: " + std::string(e.what()) + ")");
  } catch (const ros::Exception& e) {
    // Any other rosbag::BagException (cannot open the file) and the message deserialiser's
    // overruns.
    throw InputError(bag_path + ": cannot read the bag: " + e.what());
  }
}

}  // namespace kestrel::ros1
