#pragma once
// Top-view pictures of plans: the grid (free white, occupied black, unknown grey), features
// (green), roadmap samples (blue) and paths with their 1-sigma x-y covariance ellipses.
#include <opencv2/core.hpp>
#include <vector>

#include "planner/grid_environment.h"

namespace kestrel::planner::eval {

struct DrawnPath {
  std::vector<Config> nodes;
  std::vector<Mat4> covariances;  ///< at the nodes (may be empty)
  cv::Scalar colour{0, 0, 255};
};

/// `pixels_per_m` sets the scale; the image is the grid's bounding box, y up.
cv::Mat draw_plans(const GridEnvironment& env, const std::vector<Config>& samples,
                   const std::vector<DrawnPath>& paths, double pixels_per_m = 30.0);

}  // namespace kestrel::planner::eval
