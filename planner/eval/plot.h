#pragma once
// Top-view pictures of plans: the environment's free space at flight height (white; obstacles
// and unknown space dark), features (green), roadmap samples (blue) and paths with their
// 1-sigma x-y covariance ellipses.
#include <opencv2/core.hpp>
#include <vector>

#include "planner/environment.h"
#include "planner/types.h"

namespace kestrel::planner::eval {

struct DrawnPath {
  std::vector<Config> nodes;
  std::vector<Mat4> covariances;  ///< at the nodes (may be empty)
  cv::Scalar colour{0, 0, 255};
};

/// `pixels_per_m` sets the scale; the image is the environment's x-y bounds, y up; free space
/// is drawn as seen at height `z_m`.
cv::Mat draw_plans(const Environment& env, const std::vector<Config>& samples, const std::vector<DrawnPath>& paths,
                   double z_m, double pixels_per_m = 30.0);

}  // namespace kestrel::planner::eval
