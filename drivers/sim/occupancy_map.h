#pragma once
// ROS map_server occupancy maps (a YAML file naming an image), read strictly.
//
// The YAML gives `image` (relative to the YAML's folder), `resolution` (m/pixel), `origin`
// (x, y, yaw of the lower-left pixel), and optionally `negate` (default 0), `occupied_thresh`
// (0.65) and `free_thresh` (0.196). A pixel of grey value v has occupancy p = (255 - v) / 255
// (v / 255 when negated): occupied above occupied_thresh, free below free_thresh, unknown in
// between. Bad input is an InputError naming the YAML file (and line when there is one).
//
// A map may not ask for more than the bounds below: they are checked on the YAML's numbers
// and on the image's header before the image is decoded or anything is sized from them, so a
// map with `resolution: 1000` or a header claiming 10^10 pixels is one error line, never a
// grid that grows without end. The image is therefore PNG or PNM (PGM, PPM, PBM), the
// formats map_server maps come in and whose header this reader knows.

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

namespace kestrel::sim {

/// A cell finer than 1 mm only multiplies the planner's collision checks (one per half cell);
/// one coarser than 10 m is no map of a building (and puts a room's worth of features on a face).
inline constexpr double kMinMapResolution_m = 0.001;
inline constexpr double kMaxMapResolution_m = 10.0;
/// |origin x| and |origin y|: farther out, single-precision positions lose millimetres.
inline constexpr double kMaxMapOrigin_m = 1e4;
/// Width and height of the map in metres: the sim's collision index (1 m cells) and the
/// planner's roadmap over a 1 km square stay in tens of megabytes.
inline constexpr double kMaxMapSide_m = 1000.0;
/// The planner keeps about 10 bytes per cell (cells, clearance, distance transform).
inline constexpr int64_t kMaxMapPixels = 25'000'000;

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
