#include "slam/place/frame_features.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace kestrel::slam {

size_t FrameFeatures::num_points() const {
  return static_cast<size_t>(std::count_if(points.begin(), points.end(),
                                           [](const Eigen::Vector3d& p) { return !std::isnan(p.z()); }));
}

FeatureExtractor::FeatureExtractor(const FeatureOptions& options) : options_(options) {
  if (options.max_features < 1) throw std::invalid_argument("features: max_features must be >= 1");
  if (options.pyramid_levels < 1) throw std::invalid_argument("features: pyramid_levels must be >= 1");
  if (!(options.scale_factor > 1.0)) throw std::invalid_argument("features: scale_factor must be > 1");
  if (!(options.min_depth_m > 0.0 && options.max_depth_m > options.min_depth_m)) {
    throw std::invalid_argument("features: need 0 < min_depth_m < max_depth_m");
  }
  orb_ = cv::ORB::create(options.max_features, static_cast<float>(options.scale_factor),
                         options.pyramid_levels, 19, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                         options.fast_threshold);
}

FrameFeatures FeatureExtractor::extract(const RgbdFrame& frame) const {
  cv::Mat grey;
  if (frame.rgb.empty()) {
    FrameFeatures none;
    none.camera = frame.camera;
    none.descriptors = cv::Mat(0, 32, CV_8UC1);
    return none;
  }
  cv::cvtColor(frame.rgb, grey, cv::COLOR_RGB2GRAY);
  const cv::Mat depth = frame.depth_mm.empty() ? cv::Mat() : depth_to_metres(frame.depth_mm);
  return extract(grey, depth, frame.camera);
}

FrameFeatures FeatureExtractor::extract(const cv::Mat& grey, const cv::Mat& depth_m,
                                        const PinholeCamera& camera) const {
  FrameFeatures f;
  f.camera = camera;
  orb_->detectAndCompute(grey, cv::noArray(), f.keypoints, f.descriptors);
  if (f.descriptors.empty()) f.descriptors = cv::Mat(0, 32, CV_8UC1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  f.points.assign(f.keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  if (depth_m.empty()) return f;
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const int u = static_cast<int>(std::lround(f.keypoints[i].pt.x));
    const int v = static_cast<int>(std::lround(f.keypoints[i].pt.y));
    if (u < 1 || v < 1 || u >= depth_m.cols - 1 || v >= depth_m.rows - 1) continue;
    // The depth at the keypoint, unless the 3x3 neighbourhood straddles a depth edge (the
    // point would be on the background or the foreground by chance).
    float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
    int valid = 0;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const float z = depth_m.at<float>(v + dv, u + du);
        if (!(z > 0.0f)) continue;
        lo = std::min(lo, z);
        hi = std::max(hi, z);
        ++valid;
      }
    }
    const double z = static_cast<double>(depth_m.at<float>(v, u));
    if (valid < 5 || !(z >= options_.min_depth_m && z <= options_.max_depth_m)) continue;
    if (static_cast<double>(hi - lo) > options_.max_depth_spread * z) continue;
    f.points[i] = camera.backproject(f.keypoints[i].pt.x, f.keypoints[i].pt.y, z);
  }
  return f;
}

}  // namespace kestrel::slam
