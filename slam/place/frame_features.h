#pragma once
// The features SLAM keeps of a keyframe: ORB keypoints and their binary descriptors (place
// recognition and loop verification), each with its 3-D point in the camera's optical frame
// when the registered depth gives one.
//
// Invariants: keypoints, descriptor rows and points are parallel arrays; descriptors are
// CV_8UC1 with 32 bytes per row; a point without depth is NaN; valid points have
// min_depth_m <= z <= max_depth_m.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "common/camera.h"
#include "common/rgbd_frame.h"

namespace kestrel::slam {

struct FeatureOptions {
  int max_features = 1000;        ///< ORB keypoints at most
  int pyramid_levels = 8;         ///< ORB scale levels
  double scale_factor = 1.2;      ///< between ORB levels
  int fast_threshold = 12;        ///< ORB's FAST threshold (grey levels)
  double min_depth_m = 0.3;       ///< closer readings are ignored (Kinect minimum)
  double max_depth_m = 6.0;       ///< farther readings are ignored (noise grows with z^2)
  double max_depth_spread = 0.03; ///< a 3x3 depth spread above this fraction of z is an edge: no point
};

struct FrameFeatures {
  PinholeCamera camera;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;                 ///< CV_8UC1, one 32-byte row per keypoint
  std::vector<Eigen::Vector3d> points; ///< p_in_camera, NaN without depth

  size_t size() const { return keypoints.size(); }
  bool has_point(size_t i) const { return !std::isnan(points[i].z()); }
  size_t num_points() const;
};

class FeatureExtractor {
 public:
  /// Throws std::invalid_argument naming the field if an option is unusable.
  explicit FeatureExtractor(const FeatureOptions& options = {});
  /// Features of a frame; a frame without colour gives none, without depth gives no points.
  FrameFeatures extract(const RgbdFrame& frame) const;
  /// Features of a grey image with an optional depth image in metres (CV_32FC1, NaN = none).
  FrameFeatures extract(const cv::Mat& grey, const cv::Mat& depth_m, const PinholeCamera& camera) const;

 private:
  FeatureOptions options_;
  cv::Ptr<cv::ORB> orb_;
};

}  // namespace kestrel::slam
