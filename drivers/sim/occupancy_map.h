#pragma once
// ROS map_server occupancy maps (a YAML file naming an image), read strictly.
//
// The YAML gives `image` (relative to the YAML's folder), `resolution` (m/pixel), `origin`
// (x, y, yaw of the lower-left pixel), and optionally `negate` (default 0), `occupied_thresh`
// (0.65) and `free_thresh` (0.196). A pixel of grey value v has occupancy p = (255 - v) / 255
// (v / 255 when negated): occupied above occupied_thresh, free below free_thresh, unknown in
// between. Bad input is an InputError naming the YAML file (and line when there is one).

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <string>

namespace kestrel::sim {

struct OccupancyMap {
  std::string yaml_path;
  std::string image_path;
  double resolution = 0.05;  ///< metres per pixel
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< x, y, yaw of the lower-left pixel
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  cv::Mat image;  ///< CV_8UC1 grey values

  /// 255 where the map is free, 0 elsewhere (occupied or unknown).
  cv::Mat free_mask() const;
  /// Pixel (col, row), pixel centres at integers, row 0 at the top of the image -> world (x, y).
  Eigen::Affine2d T_world_pixel() const;
};

/// Reads the YAML and its image.
OccupancyMap read_occupancy_map(const std::string& yaml_path);

}  // namespace kestrel::sim
