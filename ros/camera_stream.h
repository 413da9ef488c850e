#pragma once
// A ROS RGB-D camera driver's live messages (colour and depth Images, CameraInfo, Imu) as
// kestrel's source messages, one at a time as they arrive: ros-bridge's way in. The messages
// are bag-import's (camera_source.h), the frames paired by the same rule and code: each colour
// image takes the depth image nearest in stamp within max_difference_us (tum::associate; a
// depth image may serve two colour images).
//
// Online pairing, and why it gives bag-import's pairs: each topic's images arrive in stamp
// order (an image not after the last of its topic is dropped and counted). A colour image is
// decided once a depth image stamped at or after it has arrived: its nearest depth image is then
// the last one before it or that one, both held. Depth images older than the newest colour
// image by more than the tolerance can serve no later colour image and are let go. A colour
// image waits for the first CameraInfo (unless `intrinsics`); at most kMaxPending wait (one
// second of a 30 Hz camera): beyond that the oldest is decided with the depth images there are
// (a stalled depth stream) or, before any CameraInfo, dropped and counted. When the camera goes
// quiet (a bag's end: its last colour image may have no depth image after it), the owner calls
// flush(), which decides every waiting image with the depth images held, as bag-import does at
// the end of a bag.
//
// seq counts the colour images accepted, from 0: bag-import's index in stamp order when the
// bridge hears the whole recording. IMU samples are turned into the colour images' axes (the
// body's) as bag-import turns them: by the tf tree's mount when the Imu's frame is another one
// the tree joins to the images' (no lever arm), else as published. That is decided once, when
// both frames are known: before the first colour image the samples wait (the oldest dropped
// beyond kMaxPendingImu, counted); then, while the tree does not join the frames, they wait
// kImuMountWaitUs of IMU time (or until kMaxPendingImu wait) for its mount to come (a tf_static
// published late) before going out as published. Without a tree, as published.
//
// Errors: a message that cannot be converted (cut pixels, a non-finite IMU value) throws
// InputError naming the topic and stamp and changes nothing; a stream that can never give a
// frame (an encoding kestrel does not read, a CameraInfo with no usable focal length, images
// of another size than the first, depth not the colour images' size) throws StreamError.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "common/error.h"
#include "ros/camera_source.h"
#include "ros/tf_tree.h"

namespace kestrel::ros1 {

/// A camera stream that can give no frame as it is: the bridge stops (exit 3).
class StreamError : public InputError {
 public:
  using InputError::InputError;
};

struct CameraStreamStats {
  size_t colour_images = 0;     ///< accepted (converted, in order)
  size_t depth_images = 0;
  size_t frames = 0;            ///< published
  size_t unmatched_colour = 0;  ///< no depth image within the tolerance: no frame
  size_t out_of_order = 0;      ///< images and IMU samples not after the last of their topic: dropped
  size_t without_camera = 0;    ///< colour images dropped while no CameraInfo had come
  size_t camera_infos = 0;
  size_t camera_info_changes = 0;  ///< CameraInfo messages unlike the first (the first is used)
  size_t imu_samples = 0;       ///< published
  size_t imu_empty = 0;         ///< Imu messages that measure nothing: skipped
  size_t imu_dropped_awaiting_axes = 0;  ///< before the first colour image, beyond kMaxPendingImu
  std::string imu_axes = "as published";
};

class CameraStream {
 public:
  using Publish = std::function<void(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes)>;
  static constexpr size_t kMaxPending = 30;
  static constexpr size_t kMaxPendingImu = 400;        ///< 2 s of a 200 Hz IMU
  static constexpr int64_t kImuMountWaitUs = 1'000'000;

  /// `source` names the stream in errors ("ros-bridge"). `tree` (kept by the owner, fed with
  /// `tf_topic`) gives the IMU's mount; null: IMU samples as published.
  CameraStream(CameraTopicOptions options, std::string source, Publish publish, const TfTree* tree = nullptr,
               std::string tf_topic = "");

  void colour(const sensor_msgs::Image& image);
  void depth(const sensor_msgs::Image& image);
  void camera_info(const sensor_msgs::CameraInfo& info);
  void imu(const sensor_msgs::Imu& imu);

  /// Decides every colour image still waiting (given a camera) with the depth images held,
  /// and the IMU's axes with what is known.
  void flush();
  /// True while colour images wait for a depth image or the first CameraInfo, or IMU samples
  /// for their axes.
  bool waiting() const { return !pending_colour_.empty() || !pending_imu_.empty(); }

  const CameraStreamStats& stats() const { return stats_; }
  /// The frames' camera, once known.
  const std::optional<PinholeCamera>& camera() const { return camera_; }

 private:
  struct Stamped {
    int64_t utime = 0;
    int64_t seq = 0;
    cv::Mat pixels;
  };
  std::string at(const std::string& topic, const ros::Time& stamp) const;
  void check_size(const sensor_msgs::Image& image, bool depth, const std::string& what);
  void decide();
  void decide_front();
  // Decides the IMU's axes when it can (`now`: with what is known) and publishes the samples
  // that waited for them.
  void release_imu(bool now);

  CameraTopicOptions o_;
  std::string source_;
  Publish publish_;
  CameraStreamStats stats_;
  std::optional<PinholeCamera> camera_;
  std::optional<std::pair<int, int>> colour_size_, depth_size_;
  std::string colour_frame_;
  std::deque<Stamped> pending_colour_;  // accepted, not yet decided; increasing utime
  std::deque<Stamped> depth_;           // increasing utime
  std::optional<int64_t> last_colour_utime_, last_imu_utime_;
  int64_t imu_seq_ = 0;
  const TfTree* tree_;
  std::string tf_topic_;
  struct PendingImu {
    ImuReading reading;
    std::string frame;
  };
  std::deque<PendingImu> pending_imu_;       // waiting for their axes
  std::optional<int64_t> mount_wait_from_;   // the IMU time the wait for the mount began
  bool imu_axes_decided_ = false;
  std::optional<Eigen::Matrix3d> R_camera_imu_;  // once decided: the mount's rotation, or none (as published)
};

}  // namespace kestrel::ros1
