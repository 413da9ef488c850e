#include "test/ros/bag_export_logs.h"

#include <cmath>

#include "common/rgbd_frame.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::test {

Eigen::Isometry3d body_camera() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(0.1, 0, 0);
  return T;
}

kestrel::state_t make_state(int64_t utime, const Eigen::Isometry3d& T_world_body, const Eigen::Vector3d& v_world,
                            const Eigen::Vector3d& omega_body) {
  kestrel::state_t s{};
  s.utime = utime;
  s.filter = kestrel::state_t::FILTER_EKF;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body = transport::to_message(T_world_body);
  for (int i = 0; i < 3; ++i) {
    s.velocity[i] = v_world[i];
    s.angular_velocity[i] = omega_body[i];
    s.gyro_bias[i] = 0;
    s.accel_bias[i] = 0;
  }
  s.cov_dim = 15;
  s.covariance.assign(15, std::vector<double>(15, 0.0));
  return s;
}

std::vector<kestrel::state_t> write_state_log(const std::filesystem::path& path, int n, bool with_camera) {
  transport::LogWriter log(path.string());
  std::vector<kestrel::state_t> out;
  for (int i = 0; i < n; ++i) {
    const int64_t utime = 1000000 + i * 10000;
    const double a = 0.1 * i;
    const Eigen::Isometry3d T = Eigen::Translation3d(std::cos(a), std::sin(a), 0.01 * i) *
                                Eigen::AngleAxisd(a, Eigen::Vector3d(0.2, 0.1, 1).normalized());
    kestrel::state_t s = make_state(utime, T, {-std::sin(a), std::cos(a), 0.1}, {0.01, 0.02, 1.0});
    s.seq = i;
    for (int k = 0; k < 15; ++k) s.covariance[k][k] = 1e-4 * (k + 1) * (i + 1);
    if (with_camera && i % 3 == 0) {
      RgbdFrame f;
      f.utime = utime;
      f.seq = i / 3;
      f.camera.width = 4;
      f.camera.height = 3;
      f.camera.fx = f.camera.fy = 4;
      f.camera.cx = 1.5;
      f.camera.cy = 1;
      f.T_body_camera = body_camera();
      f.depth_utime = utime + 5000;
      f.camera.distortion = {0.1, -0.05, 0.001, 0.002, 0.01};
      f.rgb = cv::Mat(3, 4, CV_8UC3);
      f.depth_mm = cv::Mat(3, 4, CV_16UC1);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
          f.rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>(10 * r + c + i), static_cast<uint8_t>(50 + r),
                                                static_cast<uint8_t>(200 - c));
          f.depth_mm.at<uint16_t>(r, c) = static_cast<uint16_t>(r == 1 && c == 2 ? 0 : 1000 + 300 * r + 7 * c + i);
        }
      log.write_message(channel::kCameraRgbd, utime, transport::encode_rgbd(f));
    }
    log.write_message(channel::kState, utime, s);
    out.push_back(s);
  }
  log.close();
  return out;
}

}  // namespace kestrel::test
