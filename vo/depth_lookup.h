#pragma once
// Depth for the detected features: each keeps a 3D point only where the registered depth image
// has a reliable reading (in range, not on a depth discontinuity: sensors/depth_image.h).
//
// The depth image is not taken at the colour image's time (Kinect: up to ~20 ms apart). With
// T_rgb_depth, the motion of the camera from depth time to RGB time (predicted from the recent
// velocity), a feature's depth is read where its point was at depth time, and the point is then
// carried to RGB time. Invariant: after attach_depth(), every feature's p_camera lies on the ray
// through its ideal pixel, with z in [min_m, max_m].

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "sensors/frame_motion.h"
#include "sensors/lens.h"
#include "vo/frame.h"
#include "vo/options.h"

namespace kestrel::vo {

/// Keeps the features of `frame` that have depth and fills their ideal pixel, point and depth
/// noise (level order and level_begin are kept up to date).
void attach_depth(const cv::Mat& depth_mm, const sensors::Lens& lens, const DepthOptions& options,
                  const sensors::FrameMotion& motion, Frame& frame);

}  // namespace kestrel::vo
