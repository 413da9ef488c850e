#pragma once
// The order in which a player emits a TUM sequence: frames, accelerometer samples and ground
// truth poses merged into one stream sorted by time (no LCM, no clock: the player paces it).
//
// Invariants of playback_schedule(): events are sorted by utime; at equal utime, IMU comes
// before ground truth and ground truth before a frame (an estimator integrates the IMU up to
// a frame before it sees the frame). The window holds the frames whose RGB time lies in
// [first + start, first + start + duration] (first = the sequence's first frame), the IMU
// samples between the window's first and last frame times, inclusive, and the poses from the
// last at or before kGroundTruthMarginUs before the first frame to the first at or after as
// long after the last (so that every frame's true pose can be interpolated, at its colour
// time and at its depth's capture, which on fr1 precedes the colour stamp by up to ~31 ms).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "drivers/tum/tum_sequence.h"

namespace kestrel::tum {

/// How far beyond the frames' colour stamps the ground truth reaches (see above).
inline constexpr int64_t kGroundTruthMarginUs = 50000;

struct PlaybackWindow {
  double start_s = 0.0;     ///< seconds after the first frame, in [0, 1e9]
  double duration_s = 0.0;  ///< seconds in [0, 1e9]; 0 = to the end
  bool imu = true;          ///< include accelerometer samples
  bool ground_truth = true; ///< include ground-truth poses
};

enum class EventKind { kImu = 0, kGroundTruth = 1, kFrame = 2 };

struct PlaybackEvent {
  int64_t utime = 0;
  EventKind kind = EventKind::kFrame;
  size_t index = 0;  ///< into frames, accelerometer() or ground_truth().poses()
};

/// The merged events of `sequence` in `window`; empty if no frame falls in it. Throws
/// std::invalid_argument unless start and duration lie in [0, 1e9] seconds.
std::vector<PlaybackEvent> playback_schedule(const TumSequence& sequence, const PlaybackWindow& window);

/// Time stamps repeat shifted by this much on each pass of a looped playback: the span of the
/// events plus the median frame interval, so that time keeps increasing across passes.
int64_t loop_period_us(const TumSequence& sequence, const std::vector<PlaybackEvent>& events);

}  // namespace kestrel::tum
