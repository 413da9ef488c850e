#pragma once
// The paper's constant VO noise model (§2: "a constant noise model fitted from data"),
// fitted against ground truth: for every successful VO update the true camera motion
// T_refcam_curcam is computed from the true body poses at the reference's and the frame's
// utimes (through the update's own camera mounting), and the error is expressed as the
// filter's residual [dp (reference camera, m); dtheta (current camera, rad)] with
// true = measured ⊞ error. The fitted sigma of each axis is the RMS of its errors (a
// bias is an error the zero-mean model must cover too); the mean is reported separately so
// that a biased VO is visible.
//
// Updates whose times the truth does not cover (outside it, or in a gap wider than
// max_gap_us) are skipped and counted.

#include <array>
#include <cstdint>
#include <vector>

#include "common/trajectory.h"
#include "estimator/estimator.h"

namespace kestrel::estimator {

struct VoNoiseFit {
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();  ///< RMS per axis
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  /// Mean over updates of the keyframe-to-frame interval, s: the model is per update, so it
  /// only transfers to a VO with similar keyframe spacing.
  double mean_interval_s = 0.0;
  /// Share of the error common to the updates against one keyframe (the estimator's
  /// --vo-keyframe-share): over every pair of updates against the same keyframe, the summed
  /// product of their whitened errors (mean removed) over the summed mean squared whitened
  /// error. Errors are
  /// whitened by each update's reported covariance (by `sigma` where it reports none), so the
  /// share does not depend on how well that covariance is scaled. 0 when no keyframe has two
  /// usable updates.
  double keyframe_share = 0.0;
  int64_t keyframes_with_pairs = 0;  ///< keyframes that contributed to keyframe_share
  /// The same share from the pairs `lag` usable updates apart only: lag 1, 2-3, 4-7, ..., 128
  /// and more (the common error fades as the view moves away from the keyframe's).
  struct LagShare {
    double share = 0.0;
    int64_t pairs = 0;
  };
  std::array<LagShare, 8> share_by_lag{};
  /// The check: the same ratio for consecutive updates either side of a re-key. The new
  /// keyframe is the frame of the update before, whose error enters the next update with the
  /// opposite sign: negative where the keyframe's part is real, positive if the common error
  /// were slow drift of another kind (a timing offset, the truth's own error).
  double share_across_rekey = 0.0;
  int64_t rekey_pairs = 0;
  /// Mean of e^T C^-1 e / 6 under each update's reported covariance C: 1 when C is right on
  /// average (a --vo-scale to try); 0 when no update reports one.
  double reported_nees = 0.0;
  int64_t used = 0;
  int64_t failed = 0;     ///< VO failures (nothing to fit)
  int64_t uncovered = 0;  ///< no ground truth at one of the two times
};

/// The error of one update against the true motion (see the file comment).
Vector6d vo_error(const VoUpdate& update, const Eigen::Isometry3d& T_world_refbody,
                  const Eigen::Isometry3d& T_world_curbody);

/// Fits the model to `updates` with `truth` = T_world_body over time. Throws InputError when
/// no update can be used (the message says why).
VoNoiseFit fit_vo_noise(const std::vector<VoUpdate>& updates, const Trajectory& truth,
                        int64_t max_gap_us = 50000);

}  // namespace kestrel::estimator
