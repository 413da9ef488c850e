#pragma once
// The frame's depth at a coarse grid, for the dense geometric term of the motion refinement
// (point-to-plane ICP from the reference's depth, vo/README.md "Open").
//
// Invariants after build_dense_depth(): the grid has floor(width / 2^level) x floor(height /
// 2^level) cells on the raw (distorted) pixel grid; cell (x, y) covers the level-0 raw pixels
// [s x, s x + s) x [s y, s y + s) (s = 2^level); a valid cell (z > 0) holds the mean of the
// readings of the block's central half (block_depths()), as the point on the ray through the
// block's centre; a valid normal (non-zero) is unit, points towards the camera and comes
// from the four neighbours' points.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "sensors/lens.h"
#include "vo/options.h"

namespace kestrel::vo {

struct DenseDepth {
  int width = 0, height = 0;  ///< cells
  int scale = 1;              ///< level-0 pixels per cell side
  std::vector<Eigen::Vector3f> points;   ///< metres, camera frame; z = 0 when invalid
  std::vector<Eigen::Vector3f> normals;  ///< unit, or zero when invalid
  // Kept between frames: the cells' rays for rays_camera, and the block depths.
  std::vector<Eigen::Vector3f> rays;
  PinholeCamera rays_camera;
  bool rays_distorted = false;
  std::vector<float> depth_scratch;

  bool empty() const { return points.empty(); }
};

/// Fills `out` from the registered depth image (millimetres) at grid level `level`.
void build_dense_depth(const cv::Mat& depth_mm, const sensors::Lens& lens, const DepthOptions& depth,
                       int level, DenseDepth& out);

/// The grid's depths (metres, 0 = invalid) at `level`, row-major: the mean of the central half
/// (each side) of every block's readings in [min_m, max_m] when at least half of them are and
/// their spread is within max_discontinuity of the smallest. SSE2 for 8-pixel blocks when
/// `allow_simd` (the same values as the scalar loop, tested).
void block_depths(const cv::Mat& depth_mm, const DepthOptions& depth, int level, bool allow_simd,
                  std::vector<float>& z);

}  // namespace kestrel::vo
