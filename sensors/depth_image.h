#pragma once
// A registered depth image as a camera model reads it: which readings are reliable, when the
// depth was captured against the colour image, and where a point seen by a rolling shutter
// lies at the frame's time. Shared by the odometry (vo/depth_lookup.h) and SLAM's keyframe
// features (slam/place/frame_features.h), so both read a frame's depth the same way.
//
// Depth is in millimetres (CV_16UC1, 0 = no reading) on the colour image's raw pixel grid.
// Invariant of reliable_depth_m(): a non-zero result is in [min_m, max_m] and its 3x3
// neighbourhood's readings spread by at most max_discontinuity of it.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "sensors/frame_motion.h"
#include "sensors/lens.h"

namespace kestrel::sensors {

/// Which depth readings are kept.
struct DepthValidity {
  double min_m = 0.3;               ///< closer readings are dropped (a Kinect's minimum range)
  double max_m = 6.0;               ///< farther readings are dropped
  double max_discontinuity = 0.05;  ///< a 3x3 spread above this fraction of the depth is an edge
};

/// Depth in metres at raw pixel (u, v) (nearest pixel), or 0 when there is no reliable reading:
/// out of range, outside the image (or on its border), or on a depth discontinuity.
float reliable_depth_m(const cv::Mat& depth_mm, float u, float v, const DepthValidity& validity);

/// When the depth image was captured against the colour image.
struct DepthTiming {
  /// Depth capture minus colour capture is the depth stamp minus the colour stamp plus
  /// offset_s (a source whose stamps are arrival times: offset_s is minus the depth's extra
  /// latency); when false, offset_s alone, whatever the stamps say.
  bool from_stamps = true;
  double offset_s = 0.0;
};

/// Depth capture time minus colour capture time, seconds. Stamps 0.1 s or more apart are not
/// one capture: 0 then (from_stamps only).
double depth_time_offset_s(const DepthTiming& timing, int64_t rgb_utime, int64_t depth_utime);

/// The point seen at raw level-0 pixel (u0, v0) at depth `z` (along the ray), carried to the
/// frame's time (the middle row's, for a rolling shutter), with its ideal pixel.
Eigen::Vector3f point_at_frame_time(const Lens& lens, const FrameMotion& motion, float u0, float v0,
                                    float z, Eigen::Vector2f* ideal);

}  // namespace kestrel::sensors
