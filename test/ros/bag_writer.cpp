#include "test/ros/bag_writer.h"

#include <cmath>
#include <filesystem>
#include <limits>

#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include "common/trajectory.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/tum/tum_camera.h"
#include "drivers/tum/tum_images.h"
#include "drivers/tum/tum_lists.h"
#include "ros/ros_convert.h"

namespace kestrel::test {

geometry_msgs::TransformStamped transform(int64_t utime, const std::string& parent, const std::string& child,
                                          const Eigen::Isometry3d& T) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros1::to_ros_time(utime);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = T.translation().x();
  t.transform.translation.y = T.translation().y();
  t.transform.translation.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

namespace fs = std::filesystem;

Eigen::Isometry3d tum_bag_mount() {
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() = (Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  M.translation() = Eigen::Vector3d(0.02, -0.045, 0.01);
  return M;
}

TumBagContents write_tum_bag(const std::string& folder, const std::string& bag_path, const TumBagOptions& options) {
  const fs::path dir(folder);
  std::vector<tum::ImageEntry> rgb = tum::read_image_list((dir / "rgb.txt").string());
  const std::vector<tum::ImageEntry> depth = tum::read_image_list((dir / "depth.txt").string());
  if (options.max_frames > 0 && rgb.size() > options.max_frames) rgb.resize(options.max_frames);
  const PinholeCamera camera = tum::camera_intrinsics(tum::detect_camera(folder));
  // Depth up to 20 ms past the last colour image, as the shared folders were trimmed.
  const int64_t last = rgb.back().utime + 20000;

  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  TumBagContents n;
  sensor_msgs::CameraInfo info;
  info.width = static_cast<uint32_t>(camera.width);
  info.height = static_cast<uint32_t>(camera.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(camera.distortion.begin(), camera.distortion.end());
  info.K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0};
  info.header.frame_id = "/openni_rgb_optical_frame";
  for (const tum::ImageEntry& e : rgb) {
    const cv::Mat pixels = tum::load_rgb((dir / e.file).string(), camera.width, camera.height, {"rgb.txt", e.line});
    sensor_msgs::Image m;
    m.header.stamp = ros1::to_ros_time(e.utime);
    m.header.frame_id = "/openni_rgb_optical_frame";
    m.width = static_cast<uint32_t>(pixels.cols);
    m.height = static_cast<uint32_t>(pixels.rows);
    m.encoding = "rgb8";
    m.step = m.width * 3;
    m.data.assign(pixels.data, pixels.data + pixels.total() * 3);
    bag.write("/camera/rgb/image_color", m.header.stamp, m);
    info.header.stamp = m.header.stamp;
    bag.write("/camera/rgb/camera_info", m.header.stamp, info);
    ++n.colour;
  }
  for (const tum::ImageEntry& e : depth) {
    if (e.utime > last) break;
    const cv::Mat raw = tum::load_depth_raw((dir / e.file).string(), camera.width, camera.height, {"depth.txt", e.line});
    sensor_msgs::Image m;
    m.header.stamp = ros1::to_ros_time(e.utime);
    m.header.frame_id = "/openni_rgb_optical_frame";
    m.width = static_cast<uint32_t>(raw.cols);
    m.height = static_cast<uint32_t>(raw.rows);
    if (options.depth_16uc1_mm) {
      m.encoding = "16UC1";
      m.step = m.width * 2;
      m.data.resize(size_t{m.step} * m.height);
      auto* out = reinterpret_cast<uint16_t*>(m.data.data());
      // TUM's 1/5000 m to millimetres, rounded to the nearest (no value is halfway: raw / 5).
      for (size_t i = 0; i < raw.total(); ++i) out[i] = static_cast<uint16_t>((raw.ptr<uint16_t>()[i] + 2) / 5);
    } else {
      m.encoding = "32FC1";
      m.step = m.width * 4;
      m.data.resize(size_t{m.step} * m.height);
      auto* out = reinterpret_cast<float*>(m.data.data());
      for (size_t i = 0; i < raw.total(); ++i) {
        const uint16_t v = raw.ptr<uint16_t>()[i];
        out[i] = v == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(v) / 5000.0f;
      }
    }
    bag.write("/camera/depth/image", m.header.stamp, m);
    ++n.depth;
  }
  for (const tum::AccelerometerSample& s : tum::read_accelerometer((dir / "accelerometer.txt").string())) {
    if (s.utime < rgb.front().utime - 20000 || s.utime > last) continue;
    const sensor_msgs::Imu m = accel_sample(s.utime, kinect::accel_to_camera(s.accel_kinect));
    bag.write("/imu", m.header.stamp, m);
    ++n.imu;
  }
  const Eigen::Isometry3d mount = tum_bag_mount();
  size_t k = 0;
  const Trajectory truth = read_tum_trajectory((dir / "groundtruth.txt").string());
  for (const StampedPose& p : truth.poses()) {
    if (p.utime < rgb.front().utime - 100000 || p.utime > last + 100000) continue;
    tf2_msgs::TFMessage m;
    // Frame names with the leading '/' of TUM's (pre-tf2) bags.
    m.transforms.push_back(transform(p.utime, "/world", "/kinect", p.T * mount.inverse()));
    if (k++ % 10 == 0) m.transforms.push_back(transform(p.utime, "/kinect", "/openni_rgb_optical_frame", mount));
    bag.write("/tf", ros1::to_ros_time(p.utime), m);
    ++n.mocap;
  }
  bag.close();
  return n;
}

sensor_msgs::Image colour_image(int64_t utime, int w, int h, const std::string& encoding) {
  sensor_msgs::Image m;
  m.header.stamp = ros1::to_ros_time(utime);
  m.width = static_cast<uint32_t>(w);
  m.height = static_cast<uint32_t>(h);
  m.encoding = encoding;
  const bool mono = encoding == "mono8";
  m.step = m.width * (mono ? 1 : 3);
  m.data.resize(size_t{m.step} * m.height);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      const uint8_t R = static_cast<uint8_t>(r * 10 + c), G = static_cast<uint8_t>(100 + r), B = static_cast<uint8_t>(200 + c);
      uint8_t* p = &m.data[size_t(r) * m.step + size_t(c) * (mono ? 1 : 3)];
      if (mono) {
        p[0] = R;
      } else if (encoding == "bgr8") {
        p[0] = B, p[1] = G, p[2] = R;
      } else {
        p[0] = R, p[1] = G, p[2] = B;
      }
    }
  }
  return m;
}

sensor_msgs::Image depth_image_mm(int64_t utime, int w, int h, uint16_t mm) {
  sensor_msgs::Image m;
  m.header.stamp = ros1::to_ros_time(utime);
  m.width = static_cast<uint32_t>(w);
  m.height = static_cast<uint32_t>(h);
  m.encoding = "16UC1";
  m.step = m.width * 2;
  m.data.resize(size_t{m.step} * m.height);
  for (size_t i = 0; i < m.data.size(); i += 2) {
    m.data[i] = static_cast<uint8_t>(mm & 0xff);  // little-endian, is_bigendian = 0
    m.data[i + 1] = static_cast<uint8_t>(mm >> 8);
  }
  return m;
}

sensor_msgs::CameraInfo camera_info(int64_t utime, int w, int h, double fx, double fy) {
  sensor_msgs::CameraInfo m;
  m.header.stamp = ros1::to_ros_time(utime);
  m.width = static_cast<uint32_t>(w);
  m.height = static_cast<uint32_t>(h);
  m.distortion_model = "plumb_bob";
  m.D = {0, 0, 0, 0, 0};
  m.K = {fx, 0, (w - 1) / 2.0, 0, fy, (h - 1) / 2.0, 0, 0, 1};
  return m;
}

sensor_msgs::Imu accel_sample(int64_t utime, const Eigen::Vector3d& accel) {
  sensor_msgs::Imu m;
  m.header.stamp = ros1::to_ros_time(utime);
  m.orientation_covariance[0] = -1.0;
  m.angular_velocity_covariance[0] = -1.0;
  m.linear_acceleration.x = accel.x();
  m.linear_acceleration.y = accel.y();
  m.linear_acceleration.z = accel.z();
  return m;
}

}  // namespace kestrel::test
