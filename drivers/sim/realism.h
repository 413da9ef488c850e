#pragma once
// Image statistics that say whether simulated frames look like a real Kinect's to the
// algorithms that consume them, measured the same way on both:
//  * FAST corners per frame (OpenCV FAST, threshold 20, non-maximum suppression, full
//    resolution grey), what a feature-based VO feeds on;
//  * the fraction of pixels with a depth reading;
//  * depth noise at 1-3 m: in every 8 x 8 block whose 64 readings all lie in 1-3 m, a plane
//    z(u, v) is fitted by least squares; the block's residual RMS divided by its mean z^2
//    estimates k in sigma_z = k z^2 (the median over blocks is reported). Blocks across
//    depth edges fit badly and are rejected (residual above 5 cm).

#include <vector>

#include "common/rgbd_frame.h"

namespace kestrel::sim {

struct FrameStats {
  int fast_corners = 0;
  double valid_depth = 0.0;          ///< fraction of pixels
  std::vector<double> noise_k;       ///< per plane block: residual RMS / z^2, 1/m
};

FrameStats frame_stats(const RgbdFrame& frame);

struct SequenceStats {
  int frames = 0;
  double fast_corners_median = 0.0;
  double valid_depth_median = 0.0;
  double noise_k_median = 0.0;       ///< over all blocks of all frames, 1/m
  int noise_blocks = 0;
};

SequenceStats summarise(const std::vector<FrameStats>& frames);

}  // namespace kestrel::sim
