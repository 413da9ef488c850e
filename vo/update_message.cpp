#include "vo/update_message.h"

#include "common/transport/convert.h"

namespace kestrel::vo {

static_assert(int(VoStatus::kOk) == kestrel::vo_update_t::STATUS_OK);
static_assert(int(VoStatus::kNoReference) == kestrel::vo_update_t::STATUS_NO_REFERENCE);
static_assert(int(VoStatus::kInsufficientFeatures) == kestrel::vo_update_t::STATUS_INSUFFICIENT_FEATURES);
static_assert(int(VoStatus::kInsufficientDepth) == kestrel::vo_update_t::STATUS_INSUFFICIENT_DEPTH);
static_assert(int(VoStatus::kInsufficientMatches) == kestrel::vo_update_t::STATUS_INSUFFICIENT_MATCHES);
static_assert(int(VoStatus::kInsufficientInliers) == kestrel::vo_update_t::STATUS_INSUFFICIENT_INLIERS);
static_assert(int(VoStatus::kOptimizationFailure) == kestrel::vo_update_t::STATUS_OPTIMIZATION_FAILURE);
static_assert(int(VoStatus::kBadInput) == kestrel::vo_update_t::STATUS_BAD_INPUT);

kestrel::vo_update_t to_message(const VoResult& r, const Eigen::Isometry3d& T_body_camera,
                                double elapsed_ms) {
  kestrel::vo_update_t m{};
  m.utime = r.utime;
  m.seq = r.seq;
  m.reference_utime = r.reference_utime;
  m.previous_utime = r.previous_utime;
  m.status = static_cast<int8_t>(r.status);
  m.flags = static_cast<int8_t>((r.new_reference ? kestrel::vo_update_t::FLAG_NEW_REFERENCE : 0) |
                                (r.fell_back_to_previous ? kestrel::vo_update_t::FLAG_FELL_BACK_TO_PREVIOUS : 0));
  const bool ok = r.status == VoStatus::kOk;
  m.T_reference_current = transport::to_message(ok ? r.T_reference_current : Eigen::Isometry3d::Identity());
  transport::covariance_to(ok ? r.covariance : Matrix6d::Zero(), m.covariance);
  m.translation_floor = ok ? r.translation_floor_m : 0.0;
  m.rotation_floor = ok ? r.rotation_floor_rad : 0.0;
  m.T_body_camera = transport::to_message(T_body_camera);
  m.num_features = r.num_features;
  m.num_features_with_depth = r.num_features_with_depth;
  m.num_matches = r.num_matches;
  m.num_inliers = r.num_inliers;
  m.num_reprojection_inliers = r.num_reprojection_inliers;
  m.mean_reprojection_error = static_cast<float>(r.mean_reprojection_error_px);
  m.fast_threshold = r.fast_threshold;
  m.elapsed_ms = static_cast<float>(elapsed_ms);
  return m;
}

kestrel::vo_update_t bad_input_message(int64_t utime, int64_t seq) {
  VoResult r;
  r.utime = utime;
  r.seq = seq;
  r.status = VoStatus::kBadInput;
  return to_message(r, Eigen::Isometry3d::Identity(), 0.0);
}

}  // namespace kestrel::vo
