#pragma once
// The initial rotation between two frames from heavily down-sampled images (Mei et al. 2008,
// as fovis does): the rotation R_cur_prev whose homography K R K^-1 best maps the previous
// image onto the current one in the least-squares sense, with a brightness offset. It is solved
// by ESM (efficient second-order minimisation) on SO(3): the Jacobian averages the current
// image's gradient at the warped pixel and the previous image's at the pixel.
//
// It ignores translation and lens distortion: it is a prior that places the matching windows,
// good to about a pixel at this resolution, not an estimate of the motion.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "common/camera.h"

namespace kestrel::vo {

struct RotationPriorResult {
  Eigen::Matrix3d R_cur_prev = Eigen::Matrix3d::Identity();
  double rms_error = 0.0;   ///< grey levels, over the pixels that overlap
  int iterations = 0;
  bool converged = false;
};

class RotationPrior {
 public:
  /// Aligns `cur` (CV_8UC1) to `prev` (CV_8UC1, same size) seen by `camera` (the camera of
  /// these images, i.e. scaled), starting from `R_init`.
  RotationPriorResult estimate(const cv::Mat& prev, const cv::Mat& cur, const PinholeCamera& camera,
                               const Eigen::Matrix3d& R_init, int max_iterations);

 private:
  cv::Mat prev_f_, cur_f_, prev_gx_, prev_gy_, cur_gx_, cur_gy_;
  std::vector<Eigen::Vector3f> jref_;
};

}  // namespace kestrel::vo
