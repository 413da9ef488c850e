#include "slam/place/frame_features.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "common/geometry/se3.h"
#include "sensors/depth_image.h"
#include "sensors/lens.h"

namespace kestrel::slam {

size_t FrameFeatures::num_points() const {
  return static_cast<size_t>(std::count_if(points.begin(), points.end(),
                                           [](const Eigen::Vector3d& p) { return !std::isnan(p.z()); }));
}

struct FeatureExtractor::LensCache {
  std::mutex mutex;
  std::shared_ptr<const sensors::Lens> lens;  // the last camera's
};

FeatureExtractor::FeatureExtractor(const FeatureOptions& options)
    : options_(options), lens_cache_(std::make_shared<LensCache>()) {
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

FrameFeatures FeatureExtractor::extract(const RgbdFrame& frame, const sensors::FrameMotion& motion) const {
  cv::Mat grey;
  if (frame.rgb.empty()) {
    FrameFeatures none;
    none.camera = frame.camera;
    none.descriptors = cv::Mat(0, 32, CV_8UC1);
    return none;
  }
  cv::cvtColor(frame.rgb, grey, cv::COLOR_RGB2GRAY);
  const cv::Mat depth = frame.depth_mm.empty() ? cv::Mat() : depth_to_metres(frame.depth_mm);
  return extract(grey, depth, frame.camera, motion);
}

double FeatureExtractor::reliable_depth(const cv::Mat& depth_m, double u_px, double v_px) const {
  const int u = static_cast<int>(std::lround(u_px));
  const int v = static_cast<int>(std::lround(v_px));
  if (u < 1 || v < 1 || u >= depth_m.cols - 1 || v >= depth_m.rows - 1) return 0.0;
  // The depth at the pixel, unless the 3x3 neighbourhood straddles a depth edge (the point
  // would be on the background or the foreground by chance).
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
  if (valid < 5 || !(z >= options_.min_depth_m && z <= options_.max_depth_m)) return 0.0;
  if (static_cast<double>(hi - lo) > options_.max_depth_spread * z) return 0.0;
  return z;
}

std::shared_ptr<const sensors::Lens> FeatureExtractor::lens_for(const PinholeCamera& camera) const {
  const std::lock_guard<std::mutex> lock(lens_cache_->mutex);
  if (!lens_cache_->lens || !lens_cache_->lens->prepared_for(camera, true)) {
    auto lens = std::make_shared<sensors::Lens>();
    lens->reset(camera, true);
    lens_cache_->lens = std::move(lens);
  }
  return lens_cache_->lens;
}

sensors::FrameMotion keyframe_motion(const vo::DepthOptions& timing, int64_t utime, int64_t depth_utime,
                                int64_t previous_utime, const Eigen::Isometry3d& T_previous_current) {
  sensors::FrameMotion motion;
  const double dt = 1e-6 * static_cast<double>(utime - previous_utime);
  if (!(dt > 0.0)) return motion;
  motion.known = true;
  motion.twist_per_s = se3::log(T_previous_current) / dt;
  motion.depth_offset_s =
      timing.compensate_time_offset ? sensors::depth_time_offset_s(timing.timing(), utime, depth_utime) : 0.0;
  motion.readout_s = timing.rolling_shutter_readout_s;
  return motion;
}

FrameFeatures FeatureExtractor::extract(const cv::Mat& grey, const cv::Mat& depth_m,
                                        const PinholeCamera& camera, const sensors::FrameMotion& motion) const {
  FrameFeatures f;
  f.camera = camera;
  orb_->detectAndCompute(grey, cv::noArray(), f.keypoints, f.descriptors);
  if (f.descriptors.empty()) f.descriptors = cv::Mat(0, 32, CV_8UC1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  f.points.assign(f.keypoints.size(), Eigen::Vector3d(nan, nan, nan));
  if (depth_m.empty()) return f;
  // The timing correction (top of frame_features.h); none for a global shutter without a
  // depth offset, whose points stay exactly as read at the keypoint.
  const bool timed = motion.known && (motion.depth_offset_s != 0.0 || motion.readout_s > 0.0);
  const bool depth_time = motion.known && motion.depth_offset_s != 0.0;
  const Eigen::Isometry3d T_rgb_depth = motion.T_rgb_depth();
  const Eigen::Isometry3d T_depth_rgb = T_rgb_depth.inverse();
  // The lens (top of frame_features.h): without distortion ideal pixels are the raw ones and
  // the untimed path below is the one keyframes always took.
  const bool distorted = camera.distorted();
  const std::shared_ptr<const sensors::Lens> lens = (timed || distorted) ? lens_for(camera) : nullptr;
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::Point2f pt = f.keypoints[i].pt;  // raw: depth is read here
    Eigen::Vector2d ideal(pt.x, pt.y);
    if (distorted) {
      ideal = lens->ideal(pt.x, pt.y).cast<double>();
      f.keypoints[i].pt = cv::Point2f(static_cast<float>(ideal.x()), static_cast<float>(ideal.y()));
    }
    double z = reliable_depth(depth_m, static_cast<double>(pt.x), static_cast<double>(pt.y));
    if (!(z > 0.0)) continue;
    if (!timed) {
      f.points[i] = camera.backproject(ideal.x(), ideal.y(), z);
      continue;
    }
    if (depth_time) {
      // Where the point seen now at this pixel was at depth time; read the depth there (at
      // that ideal pixel's raw one) and bring that point back to RGB time (its depth along
      // this keypoint's ray).
      const Eigen::Vector3d p_depth = T_depth_rgb * camera.backproject(ideal.x(), ideal.y(), z);
      if (!(p_depth.z() > 0.0)) continue;
      const Eigen::Vector2d at_depth = camera.project(p_depth);
      const Eigen::Vector2d raw_at_depth =
          distorted ? camera.distort(at_depth.x(), at_depth.y()) : at_depth;
      const double z_depth = reliable_depth(depth_m, raw_at_depth.x(), raw_at_depth.y());
      if (!(z_depth > 0.0)) continue;
      z = (T_rgb_depth * camera.backproject(at_depth.x(), at_depth.y(), z_depth)).z();
      if (!(z >= options_.min_depth_m && z <= options_.max_depth_m)) continue;
    }
    // Carried from its (raw) row's time to the middle row's (rolling shutter).
    Eigen::Vector2f pixel;
    const Eigen::Vector3d p =
        sensors::point_at_frame_time(*lens, motion, pt.x, pt.y, static_cast<float>(z), &pixel).cast<double>();
    if (!(p.z() >= options_.min_depth_m && p.z() <= options_.max_depth_m)) continue;
    f.points[i] = p;
    f.keypoints[i].pt = cv::Point2f(pixel.x(), pixel.y());
  }
  return f;
}

}  // namespace kestrel::slam
