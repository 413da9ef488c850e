#include "drivers/tum/playback.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace kestrel::tum {

std::vector<PlaybackEvent> playback_schedule(const TumSequence& sequence, const PlaybackWindow& window) {
  // 1e9 s (31 years) keeps the microsecond arithmetic below far from int64 overflow.
  constexpr double kMaxSeconds = 1e9;
  if (!(window.start_s >= 0.0 && window.start_s <= kMaxSeconds))
    throw std::invalid_argument("playback start must be between 0 and 1e9 seconds");
  if (!(window.duration_s >= 0.0 && window.duration_s <= kMaxSeconds))
    throw std::invalid_argument("playback duration must be between 0 and 1e9 seconds");
  std::vector<PlaybackEvent> events;
  if (sequence.empty()) return events;

  const int64_t begin = sequence.utime(0) + static_cast<int64_t>(std::llround(window.start_s * 1e6));
  const bool to_end = window.duration_s == 0.0;
  const int64_t end = begin + static_cast<int64_t>(std::llround(window.duration_s * 1e6));
  for (size_t i = 0; i < sequence.size(); ++i) {
    const int64_t t = sequence.utime(i);
    if (t >= begin && (to_end || t <= end)) events.push_back({t, EventKind::kFrame, i});
  }
  if (events.empty()) return events;
  const int64_t first = events.front().utime;
  const int64_t last = events.back().utime;

  if (window.imu) {
    const auto& accel = sequence.accelerometer();
    for (size_t i = 0; i < accel.size(); ++i) {
      if (accel[i].utime >= first && accel[i].utime <= last)
        events.push_back({accel[i].utime, EventKind::kImu, i});
    }
  }
  if (window.ground_truth) {
    // From the last pose at or before the margin before the first frame to the first at or
    // after it past the last one, so that every frame's true pose can be interpolated, at its
    // colour time and at its depth's (the motion capture runs at its own rate: fr1's first
    // frames come between two of its samples).
    const auto& poses = sequence.ground_truth().poses();
    size_t begin_pose = 0, end_pose = poses.size();  // [begin_pose, end_pose)
    for (size_t i = 0; i < poses.size(); ++i) {
      if (poses[i].utime <= first - kGroundTruthMarginUs) begin_pose = i;
      if (poses[i].utime >= last + kGroundTruthMarginUs) {
        end_pose = i + 1;
        break;
      }
    }
    for (size_t i = begin_pose; i < end_pose; ++i) events.push_back({poses[i].utime, EventKind::kGroundTruth, i});
  }
  std::stable_sort(events.begin(), events.end(), [](const PlaybackEvent& a, const PlaybackEvent& b) {
    return std::make_tuple(a.utime, static_cast<int>(a.kind), a.index) <
           std::make_tuple(b.utime, static_cast<int>(b.kind), b.index);
  });
  return events;
}

int64_t loop_period_us(const TumSequence& sequence, const std::vector<PlaybackEvent>& events) {
  if (events.empty()) return 0;
  std::vector<int64_t> intervals;
  for (size_t i = 1; i < sequence.size(); ++i) intervals.push_back(sequence.utime(i) - sequence.utime(i - 1));
  int64_t frame_interval = 33333;  // 30 Hz when there is a single frame
  if (!intervals.empty()) {
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
    frame_interval = intervals[intervals.size() / 2];
  }
  return events.back().utime - events.front().utime + frame_interval;
}

}  // namespace kestrel::tum
