#include "drivers/tum/player.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <stdexcept>
#include <thread>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "drivers/kinect/accelerometer.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"

namespace kestrel::tum {
namespace {

using Clock = std::chrono::steady_clock;

// Decodes the next frame on another thread while the current one is encoded and sent: PNG
// decoding is most of the work, and it keeps real-time pacing from slipping.
class FramePrefetcher {
 public:
  FramePrefetcher(const TumSequence& sequence, const std::vector<PlaybackEvent>& events)
      : sequence_(sequence), events_(events) {}

  RgbdFrame take(size_t event) {
    RgbdFrame frame = pending_event_ == event && pending_.valid()
                          ? pending_.get()
                          : sequence_.frame(events_[event].index);
    start_after(event);
    return frame;
  }

 private:
  void start_after(size_t event) {
    size_t next = event + 1;
    while (next < events_.size() && events_[next].kind != EventKind::kFrame) ++next;
    if (next == events_.size()) return;
    pending_event_ = next;
    const size_t frame_index = events_[next].index;
    pending_ = std::async(std::launch::async, [this, frame_index] { return sequence_.frame(frame_index); });
  }

  const TumSequence& sequence_;
  const std::vector<PlaybackEvent>& events_;
  size_t pending_event_ = static_cast<size_t>(-1);
  std::future<RgbdFrame> pending_;
};

kestrel::imu_t imu_message(const AccelerometerSample& s, int64_t utime, int64_t seq, bool raw_axes) {
  kestrel::imu_t m{};
  m.utime = utime;
  m.seq = seq;
  m.fields = kestrel::imu_t::HAS_ACCEL;
  const Eigen::Vector3d a = raw_axes ? s.accel_kinect : kinect::accel_to_camera(s.accel_kinect);
  for (int i = 0; i < 3; ++i) m.linear_acceleration[i] = a[i];
  return m;
}

kestrel::ground_truth_t ground_truth_message(const StampedPose& p, int64_t utime) {
  kestrel::ground_truth_t m{};
  m.utime = utime;
  m.frame = kestrel::ground_truth_t::FRAME_CAMERA;
  m.T_world_frame = transport::to_message(p.T);
  m.fields = 0;
  return m;
}

}  // namespace

PlayerStats play(const TumSequence& sequence, const std::vector<PlaybackEvent>& events,
                 const PlayerOptions& options, const PlayerSink& sink) {
  if (!(options.rate >= 0.0) || !std::isfinite(options.rate))
    throw std::invalid_argument("playback rate must be finite and >= 0");
  if (options.loop && options.rate == 0.0)
    throw std::invalid_argument("a looped playback must be paced (rate > 0)");
  PlayerStats stats;
  if (events.empty()) return stats;

  const int64_t period_us = loop_period_us(sequence, events);
  const int64_t first_utime = events.front().utime;
  const auto wall_start = Clock::now();
  int64_t imu_seq = 0;

  for (int64_t pass = 0; pass == 0 || options.loop; ++pass) {
    if (sink.stopping()) {
      stats.stopped = true;
      return stats;
    }
    ++stats.passes;
    const int64_t shift_us = pass * period_us;
    const int64_t seq_shift = pass * static_cast<int64_t>(sequence.association().rgb_images);
    FramePrefetcher prefetch(sequence, events);
    for (size_t k = 0; k < events.size(); ++k) {
      const PlaybackEvent& e = events[k];
      const int64_t utime = e.utime + shift_us;
      // Decode (and encode) before waiting, so that the wait absorbs the work.
      std::string channel;
      std::vector<uint8_t> bytes;
      switch (e.kind) {
        case EventKind::kFrame: {
          RgbdFrame f = prefetch.take(k);
          f.utime += shift_us;
          f.depth_utime += shift_us;
          f.seq += seq_shift;
          channel = channel::kCameraRgbd;
          bytes = transport::encode_message(transport::encode_rgbd(f, options.encoding));
          break;
        }
        case EventKind::kImu:
          channel = channel::kImu;
          bytes = transport::encode_message(imu_message(sequence.accelerometer()[e.index], utime,
                                                        imu_seq++, options.raw_accel_axes));
          break;
        case EventKind::kGroundTruth:
          channel = channel::kGroundTruth;
          bytes = transport::encode_message(
              ground_truth_message(sequence.ground_truth().poses()[e.index], utime));
          break;
      }

      if (options.rate > 0.0) {
        const auto due = wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                          static_cast<double>(utime - first_utime) * 1e-6 / options.rate));
        for (auto now = Clock::now(); now < due; now = Clock::now()) {
          if (sink.stopping()) break;
          sink.idle();
          std::this_thread::sleep_for(std::min<Clock::duration>(due - now, std::chrono::milliseconds(20)));
        }
        stats.max_lateness_s = std::max(
            stats.max_lateness_s, std::chrono::duration<double>(Clock::now() - due).count());
      }
      if (sink.stopping()) {
        stats.stopped = true;
        return stats;
      }
      sink.publish(channel, utime, bytes);
      ++(e.kind == EventKind::kFrame ? stats.frames
         : e.kind == EventKind::kImu ? stats.imu_samples
                                     : stats.ground_truth_poses);
    }
  }
  return stats;
}

}  // namespace kestrel::tum
