#include "ros/ros_convert.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/error.h"
#include "common/rgbd_frame.h"

namespace kestrel::ros1 {
namespace {

// sensor_msgs/image_encodings names, spelled here so that this file needs no cv_bridge.
constexpr const char* kRgb8 = "rgb8";
constexpr const char* kBgr8 = "bgr8";
constexpr const char* kMono8 = "mono8";
constexpr const char* k16UC1 = "16UC1";
constexpr const char* kMono16 = "mono16";
constexpr const char* k32FC1 = "32FC1";

int bytes_per_pixel(const std::string& encoding) {
  if (encoding == kRgb8 || encoding == kBgr8) return 3;
  if (encoding == kMono8) return 1;
  if (encoding == k16UC1 || encoding == kMono16) return 2;
  if (encoding == k32FC1) return 4;
  return 0;
}

std::string known_encodings(bool depth) {
  return depth ? "16UC1 (millimetres), mono16, 32FC1 (metres)" : "rgb8, bgr8, mono8";
}

// A view of the message's rows as a Mat of `type`, without copying (valid while `image` is).
cv::Mat rows_of(const sensor_msgs::Image& image, int type) {
  return cv::Mat(static_cast<int>(image.height), static_cast<int>(image.width), type,
                 const_cast<uint8_t*>(image.data.data()), image.step);
}

bool host_is_big_endian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

}  // namespace

int64_t to_utime(const ros::Time& t) {
  // nsec < 1e9, so the rounding carries into the next second at most once.
  return static_cast<int64_t>(t.sec) * 1000000 + (static_cast<int64_t>(t.nsec) + 500) / 1000;
}

ros::Time to_ros_time(int64_t utime) {
  if (utime < 0) throw std::invalid_argument("to_ros_time: negative time");
  return ros::Time(static_cast<uint32_t>(utime / 1000000), static_cast<uint32_t>((utime % 1000000) * 1000));
}

bool is_colour_encoding(const std::string& e) { return e == kRgb8 || e == kBgr8 || e == kMono8; }
bool is_depth_encoding(const std::string& e) { return e == k16UC1 || e == kMono16 || e == k32FC1; }

void check_image(const sensor_msgs::Image& image, bool depth, const std::string& what) {
  const bool known = depth ? is_depth_encoding(image.encoding) : is_colour_encoding(image.encoding);
  if (!known) {
    throw InputError(what + ": " + (depth ? "depth" : "colour") + " encoding '" + image.encoding +
                     "' is not one kestrel reads (" + known_encodings(depth) + ")");
  }
  if (image.width == 0 || image.height == 0 || image.width > 16384 || image.height > 16384) {
    throw InputError(what + ": image size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                     " is empty or implausible");
  }
  const uint64_t row = uint64_t{image.width} * static_cast<uint64_t>(bytes_per_pixel(image.encoding));
  if (image.step < row) {
    throw InputError(what + ": step " + std::to_string(image.step) + " is shorter than a row of " +
                     std::to_string(image.width) + " " + image.encoding + " pixels (" + std::to_string(row) + " bytes)");
  }
  // Rows are read as cv::Mat rows of whole pixels: a step that is not a whole number of
  // pixels' channels (2 bytes for 16UC1, 4 for 32FC1) is refused here, not by OpenCV.
  const uint64_t element = depth ? static_cast<uint64_t>(bytes_per_pixel(image.encoding)) : 1;
  if (image.step % element != 0) {
    throw InputError(what + ": step " + std::to_string(image.step) + " is not a whole number of " + image.encoding +
                     " pixels' " + std::to_string(element) + " bytes");
  }
  const uint64_t needed = uint64_t{image.step} * image.height;
  if (image.data.size() < needed) {
    throw InputError(what + ": " + std::to_string(image.data.size()) + " bytes of pixels, " +
                     std::to_string(needed) + " expected (" + std::to_string(image.height) + " rows of " +
                     std::to_string(image.step) + ")");
  }
}

cv::Mat colour_to_rgb(const sensor_msgs::Image& image, const std::string& what) {
  check_image(image, false, what);
  cv::Mat rgb(static_cast<int>(image.height), static_cast<int>(image.width), CV_8UC3);
  if (image.encoding == kMono8) {
    const cv::Mat grey = rows_of(image, CV_8UC1);
    for (int r = 0; r < rgb.rows; ++r) {
      const uint8_t* in = grey.ptr<uint8_t>(r);
      uint8_t* out = rgb.ptr<uint8_t>(r);
      for (int c = 0; c < rgb.cols; ++c) out[3 * c] = out[3 * c + 1] = out[3 * c + 2] = in[c];
    }
    return rgb;
  }
  const cv::Mat in = rows_of(image, CV_8UC3);
  const bool swap = image.encoding == kBgr8;
  for (int r = 0; r < rgb.rows; ++r) {
    const uint8_t* i = in.ptr<uint8_t>(r);
    uint8_t* o = rgb.ptr<uint8_t>(r);
    for (int c = 0; c < 3 * rgb.cols; c += 3) {
      o[c] = i[swap ? c + 2 : c];
      o[c + 1] = i[c + 1];
      o[c + 2] = i[swap ? c : c + 2];
    }
  }
  return rgb;
}

cv::Mat depth_to_mm(const sensor_msgs::Image& image, const std::string& what) {
  check_image(image, true, what);
  const bool swap = (image.is_bigendian != 0) != host_is_big_endian();
  if (image.encoding == k32FC1) {
    cv::Mat metres = rows_of(image, CV_32FC1).clone();
    if (swap) {
      for (int r = 0; r < metres.rows; ++r) {
        uint8_t* p = metres.ptr<uint8_t>(r);
        for (int c = 0; c < 4 * metres.cols; c += 4) {
          std::swap(p[c], p[c + 3]);
          std::swap(p[c + 1], p[c + 2]);
        }
      }
    }
    return depth_to_millimetres(metres);
  }
  cv::Mat mm = rows_of(image, CV_16UC1).clone();
  if (swap) {
    for (int r = 0; r < mm.rows; ++r) {
      uint16_t* p = mm.ptr<uint16_t>(r);
      for (int c = 0; c < mm.cols; ++c) p[c] = static_cast<uint16_t>((p[c] >> 8) | (p[c] << 8));
    }
  }
  return mm;
}

PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info, const std::string& what) {
  PinholeCamera c;
  c.width = static_cast<int>(info.width);
  c.height = static_cast<int>(info.height);
  c.fx = info.K[0];
  c.fy = info.K[4];
  c.cx = info.K[2];
  c.cy = info.K[5];
  if (info.width == 0 || info.height == 0 || info.width > 16384 || info.height > 16384)
    throw InputError(what + ": CameraInfo size " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                     " is empty or implausible");
  if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && c.fx > 0.0 && c.fy > 0.0))
    throw InputError(what + ": CameraInfo focal length fx=" + std::to_string(c.fx) + ", fy=" + std::to_string(c.fy) +
                     " (K[0], K[4]) must be finite and > 0: an uncalibrated camera (give --intrinsics)");
  if (!(std::isfinite(c.cx) && std::isfinite(c.cy)))
    throw InputError(what + ": CameraInfo principal point (K[2], K[5]) is not finite");
  const auto& d = info.D;
  const bool all_zero = std::all_of(d.begin(), d.end(), [](double v) { return v == 0.0; });
  if (!d.empty() && !all_zero) {
    const bool plumb_bob = info.distortion_model == "plumb_bob" && d.size() == 5;
    // rational_polynomial is k1 k2 p1 p2 k3 k4 k5 k6: the plumb-bob model when k4..k6 are 0.
    const bool rational_as_plumb_bob = info.distortion_model == "rational_polynomial" && d.size() == 8 &&
                                       d[5] == 0.0 && d[6] == 0.0 && d[7] == 0.0;
    if (!plumb_bob && !rational_as_plumb_bob)
      throw InputError(what + ": CameraInfo distortion model '" + info.distortion_model + "' with " +
                       std::to_string(d.size()) + " coefficients is not one kestrel models (plumb_bob: k1 k2 p1 p2 k3)");
    for (size_t i = 0; i < 5; ++i) {
      if (!std::isfinite(d[i])) throw InputError(what + ": CameraInfo distortion D[" + std::to_string(i) + "] is not finite");
      c.distortion[i] = d[i];
    }
  }
  c.validate(what.c_str());
  return c;
}

ImuReading imu_from_message(const sensor_msgs::Imu& imu, const std::string& what) {
  ImuReading r;
  r.utime = to_utime(imu.header.stamp);
  r.has_gyro = imu.angular_velocity_covariance[0] != -1.0;
  r.has_accel = imu.linear_acceleration_covariance[0] != -1.0;
  r.angular_velocity = {imu.angular_velocity.x, imu.angular_velocity.y, imu.angular_velocity.z};
  r.linear_acceleration = {imu.linear_acceleration.x, imu.linear_acceleration.y, imu.linear_acceleration.z};
  if (r.has_gyro && !r.angular_velocity.allFinite())
    throw InputError(what + ": Imu angular_velocity is not finite");
  if (r.has_accel && !r.linear_acceleration.allFinite())
    throw InputError(what + ": Imu linear_acceleration is not finite");
  if (!r.has_gyro) r.angular_velocity.setZero();
  if (!r.has_accel) r.linear_acceleration.setZero();
  return r;
}

namespace {

Eigen::Isometry3d isometry(double tx, double ty, double tz, double qx, double qy, double qz, double qw,
                           const std::string& what) {
  const Eigen::Vector3d t(tx, ty, tz);
  Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!t.allFinite() || !q.coeffs().allFinite()) throw InputError(what + ": pose is not finite");
  // Same tolerance as the LCM messages' (transport::from_message): a rounding error is
  // normalised away, anything larger is not a rotation.
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw InputError(what + ": quaternion of norm " + std::to_string(q.norm()) + " is not a rotation");
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace

Eigen::Isometry3d to_isometry(const geometry_msgs::Transform& t, const std::string& what) {
  return isometry(t.translation.x, t.translation.y, t.translation.z, t.rotation.x, t.rotation.y, t.rotation.z,
                  t.rotation.w, what);
}

Eigen::Isometry3d to_isometry(const geometry_msgs::Pose& p, const std::string& what) {
  return isometry(p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y, p.orientation.z,
                  p.orientation.w, what);
}

std::string frame_name(const std::string& name) {
  return !name.empty() && name.front() == '/' ? name.substr(1) : name;
}

}  // namespace kestrel::ros1
