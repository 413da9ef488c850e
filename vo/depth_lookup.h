#pragma once
// Depth for the detected features: each keeps a 3D point only where the registered depth image
// has a reliable reading (in range, not on a depth discontinuity).
//
// The depth image is not taken at the colour image's time (Kinect: up to ~20 ms apart). With
// T_rgb_depth, the motion of the camera from depth time to RGB time (predicted from the recent
// velocity), a feature's depth is read where its point was at depth time, and the point is then
// carried to RGB time. Invariant: after attach_depth(), every feature's p_camera lies on the ray
// through its ideal pixel, with z in [min_m, max_m].

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "vo/frame.h"
#include "vo/lens.h"
#include "vo/options.h"

namespace kestrel::vo {

/// Keeps the features of `frame` that have depth and fills their ideal pixel, point and depth
/// noise (level order and level_begin are kept up to date).
void attach_depth(const cv::Mat& depth_mm, const Lens& lens, const DepthOptions& options,
                  const FrameMotion& motion, Frame& frame);

/// The point seen at raw level-0 pixel (u0, v0) at depth `z` (along the ray), carried to the
/// frame's time (rolling shutter), with its ideal pixel.
Eigen::Vector3f point_at_frame_time(const Lens& lens, const FrameMotion& motion, float u0, float v0,
                                    float z, Eigen::Vector2f* ideal);

/// Depth capture time minus colour capture time, seconds, as `options` say to take it: from
/// the stamps plus the configured latency term (0 when they are 0.1 s or more apart: not one
/// capture), or the configured value alone.
double depth_time_offset_s(const DepthOptions& options, int64_t rgb_utime, int64_t depth_utime);

/// Depth in metres at raw pixel (u, v) (nearest pixel), or 0 when there is no reliable reading:
/// out of range, outside the image, or spread over its 3x3 neighbourhood by more than
/// max_discontinuity of its value.
float reliable_depth_m(const cv::Mat& depth_mm, float u, float v, const DepthOptions& options);

}  // namespace kestrel::vo
