#pragma once
// A frame as the odometry keeps it: its pyramid, its features with depth, their descriptors
// and a spatial index per level for windowed matching.
//
// Invariants once FrameBuilder::build() returned:
//  * features are sorted by level; level_begin[l] .. level_begin[l + 1] are those of level l;
//  * every feature has finite depth in [min_m, max_m] and a descriptor at the same index;
//  * p_camera is the feature's point in the camera frame at the frame's RGB time (`utime`),
//    on the ray through its ideal pixel.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "vo/dense_depth.h"
#include "vo/descriptor.h"
#include "sensors/frame_motion.h"
#include "vo/image_pyramid.h"

namespace kestrel::vo {

constexpr int kMaxLevels = 4;

struct Feature {
  float u = 0, v = 0;                  ///< position on its level, pixels
  float u0 = 0, v0 = 0;                ///< the same on level 0, raw (distorted) pixels
  Eigen::Vector2f ideal{0, 0};         ///< level-0 ideal pinhole pixel, where reprojection is measured
  Eigen::Vector3f p_camera{0, 0, 0};   ///< metres, optical frame at RGB time
  float depth_m = 0;                   ///< depth along the ray at the row's exposure time, metres
  float sigma_z = 0;                   ///< depth standard deviation, metres
  int16_t level = 0;
  int16_t score = 0;                   ///< FAST score
};

/// Feature indices of one level bucketed in square cells, for radius queries.
class FeatureGrid {
 public:
  void build(const std::vector<Feature>& features, int begin, int end, int width, int height,
             int cell_px);
  /// Calls f(index) for every feature within `radius` (level pixels) of (u, v).
  template <class F>
  void for_each_within(float u, float v, float radius, F&& f) const;

 private:
  int cell_ = 16, cols_ = 0, rows_ = 0;
  std::vector<int> cell_start_;  // cols_*rows_ + 1 offsets into index_
  std::vector<int> index_;
  const std::vector<Feature>* features_ = nullptr;
};

struct Frame {
  int64_t utime = 0;
  int64_t depth_utime = 0;
  int64_t seq = 0;
  ImagePyramid pyramid;
  cv::Mat coarse;  ///< heavily down-sampled grey image for the rotation prior
  sensors::FrameMotion motion;  ///< predicted motion used for its timing corrections
  std::vector<Feature> features;
  std::array<int, kMaxLevels + 1> level_begin{};
  DescriptorSet descriptors;
  DenseDepth dense;  ///< coarse depth grid, only when DenseOptions::enabled
  std::array<FeatureGrid, kMaxLevels> grids;
  int num_detected = 0;       ///< FAST corners over all levels, before bucketing
  int num_bucketed = 0;       ///< after bucketing and the border
  int fast_threshold = 0;     ///< threshold this frame was detected with
};

template <class F>
void FeatureGrid::for_each_within(float u, float v, float radius, F&& f) const {
  if (cols_ == 0) return;
  const int c0 = std::max(0, static_cast<int>((u - radius) / float(cell_)));
  const int c1 = std::min(cols_ - 1, static_cast<int>((u + radius) / float(cell_)));
  const int r0 = std::max(0, static_cast<int>((v - radius) / float(cell_)));
  const int r1 = std::min(rows_ - 1, static_cast<int>((v + radius) / float(cell_)));
  const float r2 = radius * radius;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const size_t cell = static_cast<size_t>(r * cols_ + c);
      for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const int i = index_[static_cast<size_t>(k)];
        const Feature& ft = (*features_)[static_cast<size_t>(i)];
        const float du = ft.u - u, dv = ft.v - v;
        if (du * du + dv * dv <= r2) f(i);
      }
    }
  }
}

}  // namespace kestrel::vo

namespace kestrel::vo {

/// Computes the descriptors (patches of `window_size`) and the per-level grids of frame's
/// features; call once the feature set is final.
void describe_features(Frame& frame, int window_size, float search_radius_level0_px);

}  // namespace kestrel::vo
