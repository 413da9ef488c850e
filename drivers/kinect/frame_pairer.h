#pragma once
// Pairs the Kinect's two free-running 30 Hz streams, RGB and depth, into RGB-D frames, and
// counts what was lost on the way.
//
// Times: every frame carries the device's time stamp (the Kinect's 60 MHz clock, shared by
// both streams, unwrapped to microseconds: DeviceClock) and the host time at reception. The
// pairing decisions use device time only, so they are the same however the host schedules
// the driver; host time only bounds how long an RGB frame may wait for its depth.
//
// Rule: each RGB frame is paired with the unused depth frame nearest to it in device time,
// if one lies within max_difference_us; otherwise it is counted as unpaired and dropped. An
// RGB frame is decided as soon as a depth frame at or after its time has arrived (no later
// depth can be nearer), or when wait_us of host time have passed since it arrived (the next
// depth frame was lost), or on flush(). Depth frames older than a decided RGB frame's can no
// longer be paired and are counted as unused. A depth frame may serve two RGB frames (the
// same rule as the TUM reader's, drivers/tum/association.h): when the next RGB frame's own
// depth frame was lost or lies farther, it takes the one its predecessor took, and no frame
// is lost at the door; each frame carries its depth's own time, which the VO corrects for.
//
// Lost frames: within a stream, a gap in device time of more than 1.5 frame periods counts
// round(gap / period) - 1 dropped frames; a frame not after the previous one of its stream
// is rejected (counted, never paired).

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace kestrel::kinect {

/// Unwraps the Kinect's 32-bit, 60 MHz frame time stamps into microseconds. Successive stamps
/// may go back a little (the streams interleave) but must be within 35 s of each other.
class DeviceClock {
 public:
  static constexpr int64_t kTicksPerMicrosecond = 60;
  int64_t to_microseconds(uint32_t ticks);

 private:
  bool started_ = false;
  uint32_t last_ticks_ = 0;
  int64_t last_unwrapped_ = 0;
};

struct StreamFrame {
  int64_t device_us = 0;   ///< device clock, unwrapped
  int64_t host_utime = 0;  ///< host clock at reception
  cv::Mat image;
};

struct PairedFrame {
  StreamFrame rgb;
  StreamFrame depth;
};

struct PairerOptions {
  int64_t max_difference_us = 20000;  ///< largest |t_rgb - t_depth|, device time
  int64_t wait_us = 60000;            ///< longest host-time wait of an RGB frame for its depth
  int64_t frame_period_us = 33333;    ///< nominal period of both streams (30 Hz)
};

struct PairerStats {
  int64_t rgb_frames = 0;    ///< accepted RGB frames
  int64_t depth_frames = 0;  ///< accepted depth frames
  int64_t paired = 0;
  int64_t unpaired_rgb = 0;  ///< no depth within max_difference_us
  int64_t unused_depth = 0;  ///< depth frames that served no RGB frame
  int64_t shared_depth = 0;  ///< depth frames that served a second RGB frame
  int64_t dropped_rgb = 0;   ///< inferred from gaps in device time
  int64_t dropped_depth = 0;
  int64_t out_of_order = 0;  ///< frames rejected for going back in time
};

class FramePairer {
 public:
  explicit FramePairer(PairerOptions options = {});

  void add_rgb(StreamFrame frame);
  void add_depth(StreamFrame frame);
  /// Decides a waiting RGB frame whose wait has expired by `host_utime`.
  void poll(int64_t host_utime);
  /// Decides everything still waiting (end of the stream).
  void flush();

  /// The next decided pair, in RGB order.
  std::optional<PairedFrame> next();
  const PairerStats& stats() const { return stats_; }

 private:
  void decide();
  /// Forgets the oldest waiting depth frame, counting it as unused unless it served a frame.
  void drop_oldest_depth();
  void count_gap(int64_t gap_us, int64_t& dropped) const;

  PairerOptions options_;
  PairerStats stats_;
  std::optional<StreamFrame> waiting_rgb_;
  std::deque<StreamFrame> depths_;  // depth frames that may still serve, oldest first
  std::optional<int64_t> served_us_;  // device time of the depth frame that served the last RGB frame
  std::deque<PairedFrame> ready_;
  std::optional<int64_t> last_rgb_us_;
  std::optional<int64_t> last_depth_us_;
};

}  // namespace kestrel::kinect
