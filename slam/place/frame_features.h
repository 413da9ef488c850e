#pragma once
// The features SLAM keeps of a keyframe: ORB keypoints and their binary descriptors (place
// recognition and loop verification), each with its 3-D point in the camera's optical frame
// when the registered depth gives one.
//
// Invariants: keypoints, descriptor rows and points are parallel arrays; descriptors are
// CV_8UC1 with 32 bytes per row; a point without depth is NaN; valid points have
// min_depth_m <= z <= max_depth_m.
//
// Timing (a Kinect: its depth image is captured at another time than the colour image, and
// the colour image is read row by row): given the camera's motion around the keyframe
// (sensors::FrameMotion), each keypoint's depth is read where its point was at depth time and the
// point is then carried to the frame's time (the middle row's), exactly as the odometry does
// (sensors/depth_image.h: T_rgb_depth = exp(depth_offset_s * twist), sensors::point_at_frame_time);
// the keypoint's pixel becomes that point's projection (its descriptor stays the one
// computed at the raw pixel). Without a known motion, or with a global shutter and no depth
// offset (the simulator's camera), points are read at the keypoint as they always were.
//
// Lens (common/camera.h: a source may report the distortion of its raw images, as freiburg1
// does): keypoints are detected and described on the raw image, and depth is read at the raw
// pixel (the registered depth shares its grid), but the point lies on the ray of the ideal
// pixel (sensors::Lens with the camera's distortion) and the keypoint's pixel becomes that ideal
// pixel (with timing, the point's projection): every pixel in FrameFeatures is an ideal
// pinhole pixel of `camera`, which is what the loop verifier's two-frame adjustment projects
// with. Without distortion (the simulator) nothing changes, bit for bit.
//
// Where the motion comes from (keyframe_motion()): the odometry's own estimate of the motion
// from the frame before the keyframe to the keyframe, over their stamps' interval -- the
// frame-to-frame motion the VO itself uses for this correction (it predicts it; SLAM, later,
// has it measured), available when the keyframe is made (no waiting for the next frame),
// both offline (sequence_run.cpp) and in the process (slam_adapter.cpp, from consecutive
// VO_UPDATEs); on fr1 the next frame's motion or the previous-to-next one did no better
// (slam/README.md, "Missing"). Depth offset and readout are the VO's (vo::DepthOptions of the camera's
// profile, vo/sensor_profile.h): sensors::depth_time_offset_s() of the frame's stamps when
// compensate_time_offset, else none; rolling_shutter_readout_s.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "common/camera.h"
#include "common/rgbd_frame.h"
#include "sensors/frame_motion.h"
#include "sensors/lens.h"
#include "vo/options.h"

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
  std::vector<cv::KeyPoint> keypoints; ///< detected on the raw image; pt: ideal pixel (see the top)
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
  /// `motion`: the camera's motion around the frame's time (see the top of this file).
  FrameFeatures extract(const RgbdFrame& frame, const sensors::FrameMotion& motion = {}) const;
  /// Features of a grey image with an optional depth image in metres (CV_32FC1, NaN = none).
  FrameFeatures extract(const cv::Mat& grey, const cv::Mat& depth_m, const PinholeCamera& camera,
                        const sensors::FrameMotion& motion = {}) const;

 private:
  /// Depth in metres at pixel (u, v) (nearest), or 0 when it is outside the image (one pixel
  /// of border), out of range or on a depth edge (3x3 neighbourhood).
  double reliable_depth(const cv::Mat& depth_m, double u, double v) const;
  /// The lens map of `camera` with its distortion, built once per camera and shared by
  /// copies of this extractor (thread-safe; building one is a 640 x 480 table).
  std::shared_ptr<const sensors::Lens> lens_for(const PinholeCamera& camera) const;

  struct LensCache;
  FeatureOptions options_;
  cv::Ptr<cv::ORB> orb_;
  std::shared_ptr<LensCache> lens_cache_;
};

/// The motion for a keyframe's features (see the top of this file): `T_previous_current` is
/// the odometry's motion from the previous frame (stamped `previous_utime`) to this one
/// (`utime`, depth stamped `depth_utime`); `timing` the camera's (the VO's DepthOptions).
/// Unknown when the interval is not positive.
sensors::FrameMotion keyframe_motion(const vo::DepthOptions& timing, int64_t utime, int64_t depth_utime,
                                int64_t previous_utime, const Eigen::Isometry3d& T_previous_current);

}  // namespace kestrel::slam
