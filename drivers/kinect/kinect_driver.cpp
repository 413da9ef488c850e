#include "drivers/kinect/kinect_driver.h"

#include <chrono>
#include <cmath>

#include "common/rgbd_frame.h"
#include "common/transport/channels.h"
#include "common/transport/message.h"
#include "drivers/kinect/accelerometer.h"
#include "kestrel/imu_t.hpp"

namespace kestrel::kinect {
namespace {

int64_t host_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// libfreenect hands out its own buffers for the duration of the callback only.
cv::Mat copy_of(const void* data, int type) {
  return cv::Mat(480, 640, type, const_cast<void*>(data)).clone();
}

}  // namespace

std::string summary(const PairerStats& s) {
  return "rgb " + std::to_string(s.rgb_frames) + ", depth " + std::to_string(s.depth_frames) +
         ", paired " + std::to_string(s.paired) + ", unpaired rgb " + std::to_string(s.unpaired_rgb) +
         ", unused depth " + std::to_string(s.unused_depth) + ", shared depth " + std::to_string(s.shared_depth) +
         ", dropped rgb " +
         std::to_string(s.dropped_rgb) + ", dropped depth " + std::to_string(s.dropped_depth) +
         ", out of order " + std::to_string(s.out_of_order);
}

KinectDriver::KinectDriver(const DriverOptions& options, const DepthRegistration& registration, int device_index)
    : options_(options),
      registration_(registration),
      pairer_(options.pairing),
      device_(
          device_index,
          [this](const void* data, uint32_t ticks) {
            pairer_.add_rgb({clock_.to_microseconds(ticks), host_utime(), copy_of(data, CV_8UC3)});
          },
          [this](const void* data, uint32_t ticks) {
            pairer_.add_depth({clock_.to_microseconds(ticks), host_utime(), copy_of(data, CV_16UC1)});
          }) {}

void KinectDriver::publish_frame(const PairedFrame& pair, const DriverSink& sink) {
  RgbdFrame f;
  f.utime = pair.rgb.host_utime;
  f.depth_utime = pair.depth.host_utime;
  f.seq = result_.frames;
  f.camera = registration_.calibration().rgb;
  f.sensor = sensor_model::kKinect1;
  f.T_body_camera = options_.T_body_camera;
  f.rgb = pair.rgb.image;
  f.depth_mm = registration_.register_raw(pair.depth.image);
  sink.publish(channel::kCameraRgbd, f.utime, transport::encode_message(transport::encode_rgbd(f, options_.encoding)));
  ++result_.frames;
}

void KinectDriver::publish_accel(int64_t utime, const DriverSink& sink) {
  const auto a = device_.accelerometer();
  // All three axes exactly zero is free fall or, far likelier, no reading yet (fakenect
  // before its first accelerometer record): not a measurement.
  if (!a || a->isZero(0.0)) return;
  const Eigen::Vector3d body =
      options_.raw_accel_axes ? *a : Eigen::Vector3d(options_.T_body_camera.linear() * accel_to_camera(*a));
  kestrel::imu_t m{};
  m.utime = utime;
  m.seq = imu_seq_++;
  m.fields = kestrel::imu_t::HAS_ACCEL;
  for (int i = 0; i < 3; ++i) m.linear_acceleration[i] = body[i];
  sink.publish(channel::kImu, utime, transport::encode_message(m));
  ++result_.imu_samples;
}

DriverResult KinectDriver::run(const DriverSink& sink) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto accel_period = options_.accel_rate_hz > 0.0
                                ? std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(1.0 / options_.accel_rate_hz))
                                : Clock::duration::zero();
  auto next_accel = start;
  auto next_health = start;
  auto limit_reached = [&] {
    if (options_.max_frames > 0 && result_.frames >= options_.max_frames) return true;
    return options_.duration_s > 0.0 &&
           std::chrono::duration<double>(Clock::now() - start).count() >= options_.duration_s;
  };

  while (!limit_reached()) {
    if (sink.stopping()) {
      result_.stopped = true;
      break;
    }
    if (!device_.process_events(10)) {
      result_.stream_ended = true;
      pairer_.flush();
    } else {
      pairer_.poll(host_utime());
    }
    while (!limit_reached()) {
      const auto pair = pairer_.next();
      if (!pair) break;
      publish_frame(*pair, sink);
    }
    if (result_.stream_ended) break;

    const auto now = Clock::now();
    if (accel_period > Clock::duration::zero() && now >= next_accel) {
      publish_accel(host_utime(), sink);
      // Catch up by skipping, not bursting, if the loop was held up.
      next_accel = std::max(next_accel + accel_period, now);
    }
    if (now >= next_health) {
      const PairerStats& s = pairer_.stats();
      sink.health(s.dropped_rgb + s.dropped_depth + s.out_of_order > 0, summary(s));
      next_health = now + std::chrono::seconds(1);
    }
    sink.idle();
  }
  result_.limit_reached = limit_reached();
  result_.pairing = pairer_.stats();
  return result_;
}

}  // namespace kestrel::kinect
