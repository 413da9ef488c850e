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

/// A flown track, each segment coloured by a value: green at 0, through yellow, red at
/// `full_scale` and above (a flight's true position error, say).
struct DrawnTrack {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> values;  ///< one per point
  double full_scale = 1.0;
  int thickness = 2;
};

/// `pixels_per_m` sets the scale; the image is the environment's x-y bounds, y up; free space
/// is drawn as seen at height `z_m`. Tracks are drawn under the paths.
cv::Mat draw_plans(const Environment& env, const std::vector<Config>& samples, const std::vector<DrawnPath>& paths,
                   double z_m, double pixels_per_m = 30.0, const std::vector<DrawnTrack>& tracks = {});

/// The colour draw_plans gives `value` on a track of `full_scale` (BGR).
cv::Scalar track_colour(double value, double full_scale);

/// Where draw_plans puts world point `p` (x right, y up) at `pixels_per_m`.
cv::Point to_pixel(const Environment& env, const Eigen::Vector3d& p, double pixels_per_m);

/// The part of a draw_plans image around `points`, `margin_m` beyond them on every side.
cv::Mat crop_to(const cv::Mat& image, const Environment& env, const std::vector<Eigen::Vector3d>& points,
                double margin_m, double pixels_per_m);

}  // namespace kestrel::planner::eval
