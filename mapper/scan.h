#pragma once
// One depth image turned into rays: the camera centre and, for every pixel with a reading, the
// measured point in the world frame.
//
// Points are stored as OctoMap's float point3d, because that is the precision OctoMap's ray
// insertion works in; building them once here lets the fast integrator and
// OcTree::insertPointCloud be fed exactly the same rays (the equality test and the benchmark do
// that). The pixel grid is kept, so the integrator can go from a cell to the rays through it.
//
// A source with lens distortion (common/camera.h) is read on the ideal pinhole grid: each
// node takes the reading of the raw pixel nearest to where the lens images the node's ray
// (at most half a raw pixel from it; a node imaged outside the image has no reading), so
// rays follow the lens and everything downstream stays a pinhole grid.
//
// Invariants: points.size() == valid.size() == cols * rows (row-major); points[i] is meaningful
// only where valid[i]; camera describes the grid the points came from (after decimation) and
// has no distortion.

#include <Eigen/Geometry>
#include <cstdint>
#include <octomap/Pointcloud.h>
#include <vector>

#include "common/camera.h"
#include "common/rgbd_frame.h"
#include "mapper/options.h"

namespace kestrel::mapper {

struct Scan {
  int64_t utime = 0;  ///< time of the depth image
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  PinholeCamera camera;
  octomap::point3d origin;  ///< camera centre, world frame
  int cols = 0;
  int rows = 0;
  std::vector<octomap::point3d> points;
  std::vector<uint8_t> valid;
  size_t num_points = 0;  ///< number of valid entries

  /// The valid points in grid order, as OctoMap's insertPointCloud takes them.
  octomap::Pointcloud valid_points() const;
};

/// `frame` with every `stride`-th pixel of its colour and depth images (a grid centred in the
/// image) and the camera re-scaled to match, on the ideal grid when the camera reports
/// distortion (see above; the result's camera has none); stride 1 of an undistorted frame
/// returns a shallow copy.
RgbdFrame decimate(const RgbdFrame& frame, int stride);
/// The colour part of decimate(): `rgb` (full size, of `camera`) on the same grid.
cv::Mat decimate_colour(const cv::Mat& rgb, const PinholeCamera& camera, int stride);

/// The rays of `frame` (every pixel; decimate first) seen from T_world_camera. Depth 0 (no
/// reading) and depth nearer than options.min_range_m give no ray. Throws InputError naming
/// `what` for a frame without depth, a broken frame or a non-rigid / non-finite pose.
Scan make_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
               const ScanOptions& options, const char* what);
/// The same into `scan`, reusing its storage (no allocation once it has held a frame as big).
void make_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
               const ScanOptions& options, const char* what, Scan& scan);
/// make_scan(decimate(frame, options.stride), ...) in one pass over the full-size depth image
/// (no decimated copy is made): the same scan, bit for bit.
void make_decimated_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                         const ScanOptions& options, const char* what, Scan& scan);

}  // namespace kestrel::mapper
