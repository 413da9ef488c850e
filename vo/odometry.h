#pragma once
// kestrel's visual odometry: RGB-D frames in, the motion of the camera relative to a reference
// (key) frame out, with its covariance and a status a user can act on. One instance follows one
// camera; it uses each frame's utime, never a clock, so a replay gives the same answer.
//
// Per frame (vo/README.md has the details and the figures):
//   grey + blur + pyramid -> FAST (adaptive threshold) + bucketing -> rotation prior from the
//   down-sampled images -> depth at the features (RGB/depth time offset compensated) ->
//   descriptors -> windowed mutual matching + subpixel -> max-clique inliers -> Horn ->
//   reprojection refinement -> outlier removal -> refinement.
// The reference is kept while it yields enough inliers; if the estimate against it fails, the
// previous frame is tried; a frame that fails against both is skipped, and a second failure in
// a row restarts the odometry from the current frame.
//
// Invariants: the result's T_reference_current and covariance are set exactly when status is
// kOk; reference_utime is the utime of a frame that earlier results reported (a frame that
// became the reference with new_reference); a bad frame changes no state.

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "common/geometry/se3.h"
#include "common/rgbd_frame.h"
#include "vo/feature_detector.h"
#include "vo/frame.h"
#include "sensors/lens.h"
#include "vo/matcher.h"
#include "vo/motion_estimator.h"
#include "vo/options.h"
#include "vo/rotation_prior.h"
#include "vo/status.h"

namespace kestrel::vo {

struct VoResult {
  int64_t utime = 0;
  int64_t seq = 0;
  int64_t reference_utime = 0;   ///< frame the motion is relative to (0: none)
  int64_t previous_utime = 0;    ///< last frame processed successfully before this one (0: none)
  VoStatus status = VoStatus::kNoReference;
  bool new_reference = false;    ///< this frame is the reference of the next ones
  bool fell_back_to_previous = false;
  Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  ///< of [dp; dtheta], see motion_refinement.h
  /// The covariance floors included in `covariance` (per-axis standard deviations added in
  /// quadrature, CovarianceOptions): noise of each frame's pose (timing, misregistration)
  /// rather than of this motion, so a chain of motions should count it once, not per motion.
  double translation_floor_m = 0.0;
  double rotation_floor_rad = 0.0;
  int num_features = 0;            ///< FAST detections over all levels
  int num_features_with_depth = 0;
  int num_matches = 0;
  int num_inliers = 0;
  int num_reprojection_inliers = 0;
  double mean_reprojection_error_px = 0.0;
  double pixel_sigma_px = 0.0;     ///< the pixel noise the covariance assumes (see RefinementOptions)
  int fast_threshold = 0;          ///< the threshold this frame was detected with
  std::string message;             ///< empty when ok; else what went wrong, with its numbers
};

class VisualOdometry {
 public:
  /// Throws std::invalid_argument naming the field if `options` are unusable.
  explicit VisualOdometry(const VoOptions& options = {});

  /// Processes the next frame of the stream.
  VoResult process(const RgbdFrame& frame);

  /// Forgets every frame: the next one becomes the first.
  void reset();

  const VoOptions& options() const { return options_; }

 private:
  struct Attempt {
    MotionEstimate estimate;
    const Frame* reference = nullptr;
  };

  Frame* acquire_frame();
  std::string check_input(const RgbdFrame& frame) const;
  Eigen::Isometry3d predict_prev_cur(const Frame& cur);
  Attempt estimate_against(const Frame& ref, const Frame& cur, const Eigen::Isometry3d& T_ref_cur_predicted);
  void finish(VoResult& result, const Frame& cur) const;

  VoOptions options_;
  sensors::Lens lens_;
  FastThresholdController threshold_;
  FeatureDetector detector_;
  RotationPrior rotation_prior_;
  Matcher matcher_;
  MotionEstimator estimator_;

  std::array<std::unique_ptr<Frame>, 3> pool_;
  Frame* keyframe_ = nullptr;
  Frame* previous_ = nullptr;
  Eigen::Isometry3d T_key_prev_ = Eigen::Isometry3d::Identity();
  // The last frame-to-frame motion and its duration, for the constant-velocity prediction.
  Eigen::Isometry3d T_prev_cur_last_ = Eigen::Isometry3d::Identity();
  double last_dt_s_ = 0.0;
  bool have_velocity_ = false;
  int consecutive_failures_ = 0;
  int keyframe_first_inliers_ = 0;  // the keyframe's reprojection inliers at its first match; 0 = none yet
  int64_t last_utime_ = 0;

  std::vector<Eigen::Vector2f> predicted_;
  std::vector<Match> matches_;
  cv::Mat coarse_scratch_;            // the rotation prior's intermediate halvings
  std::vector<uint16_t> coarse_row_;
};

}  // namespace kestrel::vo
