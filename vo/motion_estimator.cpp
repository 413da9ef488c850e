#include "vo/motion_estimator.h"

#include <cmath>

#include "common/geometry/align.h"
#include "common/geometry/so3.h"
#include "vo/ransac.h"

namespace kestrel::vo {

std::vector<int> MotionEstimator::find_inliers(const VoOptions& options, uint64_t seed) {
  const InlierOptions& o = options.inliers;
  if (o.method == InlierMethod::kMaxClique) {
    build_consistency_graph(ref_points_, cur_points_, variances_,
                            static_cast<float>(o.clique_threshold_m),
                            static_cast<float>(o.clique_sigmas), graph_);
    return greedy_max_clique(graph_);
  }
  RansacOptions r;
  r.hypotheses = o.ransac_hypotheses;
  r.threshold_m = static_cast<float>(o.ransac_threshold_m);
  r.block_size = o.ransac_block_size;
  r.preemptive = o.method == InlierMethod::kPreemptiveRansac;
  return ransac_inliers(ref_points_, cur_points_, r, seed);
}

MotionEstimate MotionEstimator::estimate(const Frame& ref, const Frame& cur,
                                         const std::vector<Match>& matches, const sensors::Lens& lens,
                                         const VoOptions& options, uint64_t seed) {
  MotionEstimate out;
  out.num_matches = static_cast<int>(matches.size());
  const PinholeCamera& cam = lens.camera();
  correspondences_.clear();
  ref_points_.clear();
  cur_points_.clear();
  variances_.clear();
  inliers_.clear();
  const double lateral = options.refinement.pixel_sigma / cam.fx;  // metres per metre of depth
  for (const Match& m : matches) {
    const Feature& fr = ref.features[static_cast<size_t>(m.ref)];
    const Feature& fc = cur.features[static_cast<size_t>(m.cur)];
    Correspondence c;
    c.ref_point = fr.p_camera.cast<double>();
    c.cur_point = m.cur_point.cast<double>();
    c.ref_pixel = fr.ideal.cast<double>();
    c.cur_pixel = m.cur_ideal.cast<double>();
    c.ref_sigma_z = static_cast<double>(fr.sigma_z);
    c.cur_sigma_z = static_cast<double>(fc.sigma_z);
    correspondences_.push_back(c);
    ref_points_.push_back(fr.p_camera);
    cur_points_.push_back(m.cur_point);
    const double zr = static_cast<double>(fr.p_camera.z()), zc = static_cast<double>(m.cur_point.z());
    variances_.push_back(static_cast<float>(c.ref_sigma_z * c.ref_sigma_z + c.cur_sigma_z * c.cur_sigma_z +
                                            lateral * lateral * (zr * zr + zc * zc)));
  }
  if (out.num_matches < options.min_matches) {
    out.status = VoStatus::kInsufficientMatches;
    return out;
  }

  inliers_ = find_inliers(options, seed);
  out.num_inliers = static_cast<int>(inliers_.size());
  if (out.num_inliers < options.inliers.min_inliers) {
    out.status = VoStatus::kInsufficientInliers;
    return out;
  }
  Eigen::Matrix3Xd src(3, inliers_.size()), dst(3, inliers_.size());
  for (size_t k = 0; k < inliers_.size(); ++k) {
    const Correspondence& c = correspondences_[static_cast<size_t>(inliers_[k])];
    src.col(static_cast<Eigen::Index>(k)) = c.cur_point;
    dst.col(static_cast<Eigen::Index>(k)) = c.ref_point;
  }
  const auto horn = align_rigid(src, dst);
  if (!horn) {
    out.status = VoStatus::kInsufficientInliers;  // degenerate: collinear inliers
    return out;
  }
  Eigen::Isometry3d T = *horn;
  const RefinementOptions& ro = options.refinement;
  RefinementResult refined;
  if (ro.enabled) {
    // With the dense term a second refinement always follows and reports the information.
    const bool dense = options.dense.enabled && !ref.dense.empty() && !cur.dense.empty();
    refined = refine_motion(correspondences_, inliers_, cam, T, ro, nullptr,
                            dense ? Information::kSkip : Information::kReport);
    // Drop the matches the refined motion cannot explain, then refine on the rest.
    std::vector<int> kept;
    kept.reserve(inliers_.size());
    for (int i : inliers_)
      if (reprojection_error_px(correspondences_[static_cast<size_t>(i)], cam, refined.T_ref_cur,
                                ro.bidirectional) <= ro.outlier_threshold_px)
        kept.push_back(i);
    const bool dropped_any = kept.size() != inliers_.size();
    inliers_.swap(kept);
    if (static_cast<int>(inliers_.size()) < ro.min_inliers) {
      out.num_reprojection_inliers = static_cast<int>(inliers_.size());
      out.status = VoStatus::kOptimizationFailure;
      return out;
    }
    // With nothing dropped the second refinement would start at the first one's optimum.
    if (dense) {
      DenseTerm term;
      term.ref = &ref.dense;
      term.cur = &cur.dense;
      term.options = options.dense;
      term.sigma_z_coeff = options.depth.sigma_z_coeff;
      term.use_distortion = lens.distorted();
      refined = refine_motion(correspondences_, inliers_, cam, refined.T_ref_cur, ro, &term);
    } else if (dropped_any) {
      refined = refine_motion(correspondences_, inliers_, cam, refined.T_ref_cur, ro);
    }
    T = refined.T_ref_cur;
  } else {
    // Absolute orientation only: the information at Horn's estimate still gives a covariance.
    RefinementOptions evaluate = ro;
    evaluate.max_iterations = 0;
    refined = refine_motion(correspondences_, inliers_, cam, T, evaluate);
  }
  out.num_reprojection_inliers = static_cast<int>(inliers_.size());
  double sum = 0.0;
  for (int i : inliers_)
    sum += reprojection_error_px(correspondences_[static_cast<size_t>(i)], cam, T, ro.bidirectional);
  out.mean_reprojection_error_px = inliers_.empty() ? 0.0 : sum / double(inliers_.size());
  const Eigen::LDLT<Matrix6d> ldlt(refined.information);
  if (!se3::is_valid(T, 1e-6) || ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) {
    out.status = VoStatus::kOptimizationFailure;
    return out;
  }
  out.T_ref_cur = T;
  out.covariance = ldlt.solve(Matrix6d::Identity());
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  out.model_covariance = out.covariance;
  out.pixel_sigma_px = refined.pixel_sigma;
  const CovarianceOptions& co = options.covariance;
  out.covariance *= co.model_scale;
  const double angle = so3::angle(T.linear());
  const double st = std::hypot(co.translation_floor_m, co.translation_per_rad_m * angle);
  const double sr = std::hypot(co.rotation_floor_rad, co.rotation_per_rad * angle);
  out.covariance.diagonal().head<3>().array() += st * st;
  out.covariance.diagonal().tail<3>().array() += sr * sr;
  out.status = VoStatus::kOk;
  return out;
}

}  // namespace kestrel::vo
