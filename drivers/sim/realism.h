#pragma once
// Image statistics that say whether simulated frames look like a real Kinect's to the
// algorithms that consume them, measured the same way on both:
//  * FAST corners per frame (OpenCV FAST, threshold 20, non-maximum suppression, full
//    resolution grey), what a feature-based VO feeds on;
//  * the fraction of pixels with a depth reading;
//  * depth noise at 1-3 m: in every 8 x 8 block whose 64 readings all lie in 1-3 m, a plane
//    z(u, v) is fitted by least squares; the block's residual RMS divided by its mean z^2
//    estimates k in sigma_z = k z^2 (the median over blocks is reported). Blocks across
//    depth edges fit badly and are rejected (residual above 5 cm);
//  * exposure: the mean grey level of the image and the fraction of its pixels at 250 or more
//    (clipped highlights: no texture left for features there).

#include <vector>

#include "common/rgbd_frame.h"

namespace kestrel::sim {

struct FrameStats {
  int fast_corners = 0;
  double valid_depth = 0.0;          ///< fraction of pixels
  std::vector<double> noise_k;       ///< per plane block: residual RMS / z^2, 1/m
  double mean_grey = 0.0;            ///< 0..255
  double saturated = 0.0;            ///< fraction of pixels whose grey is >= 250
};

FrameStats frame_stats(const RgbdFrame& frame);

struct SequenceStats {
  int frames = 0;
  double fast_corners_median = 0.0;
  double valid_depth_median = 0.0;
  double noise_k_median = 0.0;       ///< over all blocks of all frames, 1/m
  int noise_blocks = 0;
  double mean_grey_median = 0.0;
  double mean_grey_p95 = 0.0;        ///< 95th percentile over the frames
  double mean_grey_max = 0.0;
  double saturated_median = 0.0;
  double saturated_max = 0.0;
  double frames_over_a_tenth_saturated = 0.0;  ///< fraction of frames with more than 10 % of pixels at 250+
};

SequenceStats summarise(const std::vector<FrameStats>& frames);

}  // namespace kestrel::sim
