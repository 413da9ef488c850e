#pragma once
// Motion from matches, the steps 5 and 6 of the pipeline: inliers (greedy max-clique on the
// distance-preservation graph, or RANSAC / preemptive RANSAC), absolute orientation (Horn) on
// the inliers, reprojection refinement, removal of the matches whose reprojection error
// exceeds the threshold, and refinement again (with the dense depth term when enabled).
//
// Invariant: status is kOk exactly when T_ref_cur and covariance hold an estimate from at least
// RefinementOptions::min_inliers reprojection inliers (InlierOptions::min_inliers without
// refinement).

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "common/geometry/se3.h"
#include "vo/frame.h"
#include "sensors/lens.h"
#include "vo/matcher.h"
#include "vo/max_clique.h"
#include "vo/motion_refinement.h"
#include "vo/options.h"
#include "vo/status.h"

namespace kestrel::vo {

struct MotionEstimate {
  VoStatus status = VoStatus::kInsufficientMatches;
  Eigen::Isometry3d T_ref_cur = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();        ///< reported: model_scale * model + floors
  Matrix6d model_covariance = Matrix6d::Zero();  ///< the refinement's own (pixel and depth noise)
  int num_matches = 0;
  int num_inliers = 0;                ///< after max-clique / RANSAC
  int num_reprojection_inliers = 0;   ///< after outlier removal
  double mean_reprojection_error_px = 0.0;
  double pixel_sigma_px = 0.0;        ///< the pixel noise model_covariance assumes
};

class MotionEstimator {
 public:
  /// Estimates T_ref_cur from `matches` between `ref` and `cur`; `seed` drives RANSAC.
  MotionEstimate estimate(const Frame& ref, const Frame& cur, const std::vector<Match>& matches,
                          const sensors::Lens& lens, const VoOptions& options, uint64_t seed);

  /// The correspondences and final inliers of the last estimate (for diagnostics and tests).
  const std::vector<Correspondence>& correspondences() const { return correspondences_; }
  const std::vector<int>& inliers() const { return inliers_; }

 private:
  std::vector<int> find_inliers(const VoOptions& options, uint64_t seed);

  std::vector<Correspondence> correspondences_;
  std::vector<Eigen::Vector3f> ref_points_, cur_points_;
  std::vector<float> variances_;
  BitGraph graph_;
  std::vector<int> inliers_;
};

}  // namespace kestrel::vo
