// kestrel-kinect: a Kinect (v1) through libfreenect -> CAMERA_RGBD (depth registered to the
// RGB camera, millimetres) and IMU (accelerometer). Publishes on LCM, or writes an LCM log
// (--log). Runs unchanged on a fakenect recording. See README.md.

#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>
#include <optional>

#include "common/cli.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/node.h"
#include "drivers/kinect/calibration_options.h"
#include "drivers/kinect/encoding_options.h"
#include "drivers/kinect/kinect_driver.h"

namespace {

using namespace kestrel;

struct Options {
  int device = 0;
  std::string log;
  std::string lcm_url;
  int64_t frames = 0;
  double duration_s = 0.0;
  double accel_rate_hz = 100.0;
  bool raw_accel_axes = false;
  double max_dt_s = 0.02;
  double pair_wait_s = 0.06;
  std::vector<double> body_camera_pose{0, 0, 0, 1, 0, 0, 0};
  kinect::CalibrationOptions calibration;
  kinect::EncodingOptions encoding;
};

void add_options(cli::App& app, Options& o) {
  app.add_option("--device", o.device, "Index of the Kinect to open")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--log", o.log, "Write an LCM log here instead of publishing");
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--frames", o.frames, "Stop after this many frames (0 = never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "Stop after this many seconds (0 = never)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--accel-rate", o.accel_rate_hz, "Accelerometer reads per second (0 = none)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_flag("--raw-accel-axes", o.raw_accel_axes,
               "IMU on the accelerometer's own axes instead of the body frame");
  app.add_option("--max-dt", o.max_dt_s, "Largest RGB-depth time difference of a frame, seconds")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--pair-wait", o.pair_wait_s, "Longest wait of an RGB frame for its depth, seconds")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--body-camera-pose", o.body_camera_pose,
                 "T_body_camera as x,y,z,qw,qx,qy,qz (metres; camera optical frame in the body frame)")
      ->expected(7)
      ->delimiter(',')
      ->capture_default_str();
  o.calibration.add_to(app);
  o.encoding.add_to(app);
}

Eigen::Isometry3d body_camera_pose(const std::vector<double>& v) {
  const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  const Eigen::Vector3d t(v[0], v[1], v[2]);
  if (!t.allFinite() || !q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-3)
    throw CLI::ValidationError("--body-camera-pose", "needs finite values and a unit quaternion");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

int run(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  kinect::DriverOptions d;
  d.max_frames = o.frames;
  d.duration_s = o.duration_s;
  d.accel_rate_hz = o.accel_rate_hz;
  d.raw_accel_axes = o.raw_accel_axes;
  d.pairing.max_difference_us = std::llround(o.max_dt_s * 1e6);
  d.pairing.wait_us = std::llround(o.pair_wait_s * 1e6);
  d.T_body_camera = body_camera_pose(o.body_camera_pose);
  d.encoding = o.encoding.encoding();
  const kinect::DepthRegistration registration(o.calibration.calibration());

  std::optional<kinect::KinectDriver> driver;
  try {
    driver.emplace(d, registration, o.device);
  } catch (const kinect::DeviceUnavailable& e) {
    std::cerr << "kestrel-kinect: error: " << e.what() << "\n";
    return kExitUnavailable;
  }
  spdlog::info("streaming from {}", driver->device().is_fakenect()
                                        ? "a fakenect recording (" + driver->device().library() + ")"
                                        : "Kinect " + std::to_string(o.device));

  kinect::DriverSink sink;
  kinect::DriverResult result;
  if (!o.log.empty()) {
    catch_interrupts();
    transport::LogWriter log(o.log);
    sink.publish = [&](const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
      log.write(channel, utime, bytes);
    };
    sink.stopping = [] { return interrupted(); };
    result = driver->run(sink);
    log.close();
  } else {
    std::optional<transport::Node> node;
    node.emplace("kinect", o.lcm_url);  // UnavailableError: exit 4
    node->advertise(channel::kCameraRgbd);
    node->advertise(channel::kImu);
    node->set_health(kestrel::process_status_t::STATE_RUNNING, "");
    sink.publish = [&](const std::string& channel, int64_t, const std::vector<uint8_t>& bytes) {
      node->publish_bytes(channel, bytes);
    };
    sink.stopping = [&] { return node->stopping(); };
    sink.idle = [&] { node->spin_once(0); };
    sink.health = [&](bool degraded, const std::string& summary) {
      node->set_health(degraded ? kestrel::process_status_t::STATE_DEGRADED
                                : kestrel::process_status_t::STATE_RUNNING,
                       summary);
    };
    result = driver->run(sink);
  }

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "frames published: " << result.frames << "\n"
            << "IMU samples published: " << result.imu_samples << "\n"
            << "streams: " << kinect::summary(result.pairing) << "\n"
            << "time taken: " << seconds << " s\n";

  if (result.stream_ended && !result.limit_reached) {
    if (driver->device().is_fakenect()) {
      spdlog::info("end of the fakenect recording");
      return kExitOk;
    }
    std::cerr << "kestrel-kinect: error: the Kinect stopped delivering (unplugged?)\n";
    return kExitUnavailable;
  }
  // An open-ended run is ended by SIGINT as a matter of course; one with a limit was cut short.
  const bool bounded = o.frames > 0 || o.duration_s > 0.0;
  return result.stopped && bounded ? kExitInterrupted : kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("kinect", "Kinect (libfreenect) -> CAMERA_RGBD with registered depth, and IMU");
  Options options;
  add_options(app, options);
  return app.run(argc, argv, [&] { return run(options); });
}
