#include "ros/camera_stream.h"

#include "common/time.h"
#include "common/transport/channels.h"
#include "drivers/tum/association.h"

namespace kestrel::ros1 {

CameraStream::CameraStream(CameraTopicOptions options, std::string source, Publish publish, const TfTree* tree,
                           std::string tf_topic)
    : o_(std::move(options)),
      source_(std::move(source)),
      publish_(std::move(publish)),
      tree_(tree),
      tf_topic_(std::move(tf_topic)) {}

std::string CameraStream::at(const std::string& topic, const ros::Time& stamp) const {
  return source_ + ": " + topic + " at " + format_seconds(to_utime(stamp)) + " s";
}

// The checks bag-import makes over the whole bag, made as the first images come.
void CameraStream::check_size(const sensor_msgs::Image& image, bool depth, const std::string& what) {
  // An encoding it does not read fails every image of the topic; a cut image is one message.
  const bool known = depth ? is_depth_encoding(image.encoding) : is_colour_encoding(image.encoding);
  try {
    check_image(image, depth, what);
  } catch (const InputError& e) {
    if (!known) throw StreamError(e.what());
    throw;
  }
  const std::pair<int, int> size{static_cast<int>(image.width), static_cast<int>(image.height)};
  auto& first = depth ? depth_size_ : colour_size_;
  if (!first) {
    first = size;
  } else if (*first != size) {
    throw StreamError(what + ": image is " + std::to_string(size.first) + "x" + std::to_string(size.second) +
                      ", the topic's first was " + std::to_string(first->first) + "x" + std::to_string(first->second));
  }
  try {
    if (colour_size_ && depth_size_)
      check_depth_size(colour_size_->first, colour_size_->second, depth_size_->first, depth_size_->second, o_, source_);
    if (colour_size_ && camera_) check_camera_size(*camera_, colour_size_->first, colour_size_->second, o_, source_);
  } catch (const StreamError&) {
    throw;
  } catch (const InputError& e) {
    throw StreamError(e.what());
  }
}

void CameraStream::colour(const sensor_msgs::Image& image) {
  const std::string what = at(o_.colour_topic, image.header.stamp);
  check_size(image, false, what);
  const int64_t utime = to_utime(image.header.stamp);
  if (last_colour_utime_ && utime <= *last_colour_utime_) {
    ++stats_.out_of_order;
    return;
  }
  cv::Mat rgb = colour_to_rgb(image, what);
  if (colour_frame_.empty()) {
    colour_frame_ = frame_name(image.header.frame_id);
    release_imu(false);
  }
  if (!camera_ && o_.intrinsics) camera_ = intrinsics_camera(*o_.intrinsics, rgb.cols, rgb.rows);
  last_colour_utime_ = utime;
  pending_colour_.push_back({utime, static_cast<int64_t>(stats_.colour_images++), std::move(rgb)});
  decide();
}

void CameraStream::depth(const sensor_msgs::Image& image) {
  const std::string what = at(o_.depth_topic, image.header.stamp);
  check_size(image, true, what);
  const int64_t utime = to_utime(image.header.stamp);
  if (!depth_.empty() && utime <= depth_.back().utime) {
    ++stats_.out_of_order;
    return;
  }
  depth_.push_back({utime, 0, depth_to_mm(image, what)});
  ++stats_.depth_images;
  decide();
}

void CameraStream::camera_info(const sensor_msgs::CameraInfo& info) {
  if (o_.intrinsics) return;
  PinholeCamera c;
  try {
    c = camera_from_info(info, at(o_.camera_info_topic, info.header.stamp));
  } catch (const InputError& e) {
    throw StreamError(std::string(e.what()) + " (or give --camera-info-topic)");
  }
  if (stats_.camera_infos++ == 0) {
    camera_ = c;
    if (colour_size_) {
      try {
        check_camera_size(c, colour_size_->first, colour_size_->second, o_, source_);
      } catch (const InputError& e) {
        throw StreamError(e.what());
      }
    }
    decide();
  } else if (!same_camera(c, *camera_)) {
    ++stats_.camera_info_changes;
  }
}

void CameraStream::imu(const sensor_msgs::Imu& message) {
  const ImuReading r = imu_from_message(message, at(o_.imu_topic, message.header.stamp));
  if (!r.has_gyro && !r.has_accel) {
    ++stats_.imu_empty;
    return;
  }
  if (last_imu_utime_ && r.utime <= *last_imu_utime_) {
    ++stats_.out_of_order;
    return;
  }
  last_imu_utime_ = r.utime;
  pending_imu_.push_back({r, frame_name(message.header.frame_id)});
  if (colour_frame_.empty()) {
    while (pending_imu_.size() > kMaxPendingImu) {
      pending_imu_.pop_front();
      ++stats_.imu_dropped_awaiting_axes;
    }
  }
  release_imu(pending_imu_.size() >= kMaxPendingImu && !colour_frame_.empty());
}

void CameraStream::release_imu(bool now) {
  if (pending_imu_.empty()) return;
  if (!imu_axes_decided_) {
    const std::string& frame = pending_imu_.front().frame;
    const int64_t first_utime = pending_imu_.front().reading.utime;
    if (!tree_) {
      stats_.imu_axes = frame.empty() ? "as published" : "as published ('" + frame + "'; no tf read)";
    } else if (colour_frame_.empty() && !frame.empty() && !now) {
      return;  // the images' frame comes with the first colour image
    } else {
      ImuAxes axes = imu_axes(*tree_, frame, colour_frame_, first_utime, tf_topic_);
      const bool unjoined = !axes.R_camera_imu && !frame.empty() && frame != colour_frame_;
      if (unjoined && !now &&
          (!mount_wait_from_ || pending_imu_.back().reading.utime - *mount_wait_from_ < kImuMountWaitUs)) {
        // The mount may come yet (a tf_static published late).
        if (!mount_wait_from_) mount_wait_from_ = pending_imu_.back().reading.utime;
        return;
      }
      R_camera_imu_ = axes.R_camera_imu;
      stats_.imu_axes = std::move(axes.description);
    }
    imu_axes_decided_ = true;
  }
  while (!pending_imu_.empty()) {
    ImuReading r = pending_imu_.front().reading;
    if (R_camera_imu_) {
      r.angular_velocity = *R_camera_imu_ * r.angular_velocity;
      r.linear_acceleration = *R_camera_imu_ * r.linear_acceleration;
    }
    publish_(channel::kImu, r.utime, imu_message(r, imu_seq_));
    ++imu_seq_;
    ++stats_.imu_samples;
    pending_imu_.pop_front();
  }
}

void CameraStream::decide() {
  while (!pending_colour_.empty()) {
    const bool overfull = pending_colour_.size() > kMaxPending;
    if (!camera_) {
      if (!overfull) return;
      pending_colour_.pop_front();
      ++stats_.without_camera;
      continue;
    }
    const bool depth_after = !depth_.empty() && depth_.back().utime >= pending_colour_.front().utime;
    if (!depth_after && !overfull) break;
    decide_front();
  }
  // Depth images no colour image to come can take: older than the next colour image to decide
  // (or the last one seen) by more than the tolerance; and never more than a second's worth
  // when the colour stream stalls.
  const std::optional<int64_t> next_colour =
      pending_colour_.empty() ? last_colour_utime_ : std::optional<int64_t>(pending_colour_.front().utime);
  while (!depth_.empty() && next_colour && *next_colour - depth_.front().utime > o_.max_difference_us) depth_.pop_front();
  while (depth_.size() > 2 * kMaxPending) depth_.pop_front();
}

void CameraStream::flush() {
  release_imu(true);
  if (!camera_) return;
  while (!pending_colour_.empty()) decide_front();
}

// The oldest pending colour image with its nearest depth image among those held, by the TUM
// reader's rule and code.
void CameraStream::decide_front() {
  Stamped c = std::move(pending_colour_.front());
  pending_colour_.pop_front();
  std::vector<int64_t> depth_times;
  depth_times.reserve(depth_.size());
  for (const Stamped& d : depth_) depth_times.push_back(d.utime);
  const tum::Association a = tum::associate({c.utime}, depth_times, o_.max_difference_us);
  if (a.pairs.empty()) {
    ++stats_.unmatched_colour;
    return;
  }
  const Stamped& d = depth_[a.pairs.front().b];
  publish_(channel::kCameraRgbd, c.utime, frame_message(c.utime, d.utime, c.seq, *camera_, c.pixels, d.pixels, o_));
  ++stats_.frames;
}

}  // namespace kestrel::ros1
