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
#include <memory>
#include <string>

#include "common/geometry/se3.h"
#include "common/rgbd_frame.h"
#include "vo/options.h"
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
  ~VisualOdometry();
  VisualOdometry(VisualOdometry&&) noexcept;
  VisualOdometry& operator=(VisualOdometry&&) noexcept;

  /// Processes the next frame of the stream.
  VoResult process(const RgbdFrame& frame);

  /// Forgets every frame: the next one becomes the first.
  void reset();

  const VoOptions& options() const;

 private:
  // The pipeline's stages and the frames it keeps (odometry.cpp): internals, so that this
  // header is all another component sees of the odometry.
  class Pipeline;
  std::unique_ptr<Pipeline> pipeline_;
};

}  // namespace kestrel::vo
