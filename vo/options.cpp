#include "vo/options.h"

#include <cmath>
#include <stdexcept>

#include "vo/frame.h"

namespace kestrel::vo {
namespace {

void require(bool ok, const char* field, const char* why) {
  if (!ok) throw std::invalid_argument(std::string("vo option ") + field + ": " + why);
}

}  // namespace

void VoOptions::validate() const {
  require(pyramid.levels >= 1 && pyramid.levels <= kMaxLevels, "pyramid.levels", "must be 1..4");
  require(pyramid.blur_sigma >= 0.0 && pyramid.blur_sigma <= 5.0, "pyramid.blur_sigma", "must be 0..5");
  require(fast.threshold >= 1 && fast.threshold <= 254, "fast.threshold", "must be 1..254");
  require(fast.min_threshold >= 1 && fast.min_threshold <= fast.max_threshold &&
              fast.max_threshold <= 254,
          "fast.min_threshold/max_threshold", "must satisfy 1 <= min <= max <= 254");
  require(fast.target_pixels_per_feature > 0.0, "fast.target_pixels_per_feature", "must be > 0");
  require(fast.adaptive_gain >= 0.0, "fast.adaptive_gain", "must be >= 0");
  require(bucket.width_px > 0 && bucket.height_px > 0, "bucket.width_px/height_px", "must be > 0");
  require(bucket.max_per_bucket > 0, "bucket.max_per_bucket", "must be > 0");
  require(depth.min_m > 0.0 && depth.min_m < depth.max_m, "depth.min_m/max_m", "need 0 < min < max");
  require(depth.max_discontinuity > 0.0, "depth.max_discontinuity", "must be > 0");
  require(depth.sigma_z_coeff >= 0.0, "depth.sigma_z_coeff", "must be >= 0");
  require(std::abs(depth.time_offset_s) < 0.1, "depth.time_offset_s", "must be within (-0.1, 0.1)");
  require(depth.rolling_shutter_readout_s >= 0.0 && depth.rolling_shutter_readout_s < 0.1,
          "depth.rolling_shutter_readout_s", "must be in [0, 0.1)");
  require(rotation_prior.downsample_level >= 1 && rotation_prior.downsample_level <= 6,
          "rotation_prior.downsample_level", "must be 1..6");
  require(rotation_prior.max_iterations >= 1, "rotation_prior.max_iterations", "must be >= 1");
  require(match.window_size >= 3 && match.window_size <= 15 && match.window_size % 2 == 1,
          "match.window_size", "must be odd, 3..15");
  require(match.search_radius_px > 0.0, "match.search_radius_px", "must be > 0");
  require(match.max_sad_per_pixel > 0 && match.max_sad_per_pixel <= 255, "match.max_sad_per_pixel",
          "must be 1..255");
  require(match.max_subpixel_shift_px > 0.0 && match.max_subpixel_shift_px <= 4.0,
          "match.max_subpixel_shift_px", "must be in (0, 4]");
  require(inliers.clique_threshold_m > 0.0, "inliers.clique_threshold_m", "must be > 0");
  require(inliers.clique_sigmas >= 0.0, "inliers.clique_sigmas", "must be >= 0");
  require(inliers.ransac_hypotheses >= 1, "inliers.ransac_hypotheses", "must be >= 1");
  require(inliers.ransac_threshold_m > 0.0, "inliers.ransac_threshold_m", "must be > 0");
  require(inliers.ransac_block_size >= 1, "inliers.ransac_block_size", "must be >= 1");
  require(inliers.min_inliers >= 3, "inliers.min_inliers", "must be >= 3");
  require(refinement.pixel_sigma > 0.0, "refinement.pixel_sigma", "must be > 0");
  require(refinement.min_pixel_sigma > 0.0, "refinement.min_pixel_sigma", "must be > 0");
  require(refinement.huber_px >= 0.0, "refinement.huber_px", "must be >= 0");
  require(refinement.outlier_threshold_px > 0.0, "refinement.outlier_threshold_px", "must be > 0");
  require(refinement.max_iterations >= 1, "refinement.max_iterations", "must be >= 1");
  require(refinement.min_inliers >= 3, "refinement.min_inliers", "must be >= 3");
  require(dense.level >= 0 && dense.level <= 4, "dense.level", "must be 0..4");
  require(dense.stride >= 1, "dense.stride", "must be >= 1");
  require(dense.weight >= 0.0, "dense.weight", "must be >= 0");
  require(dense.max_distance_m > 0.0, "dense.max_distance_m", "must be > 0");
  require(dense.max_normal_angle_deg > 0.0 && dense.max_normal_angle_deg <= 180.0,
          "dense.max_normal_angle_deg", "must be in (0, 180]");
  require(dense.sigma_floor_mm >= 0.0, "dense.sigma_floor_mm", "must be >= 0");
  require(dense.huber_sigmas >= 0.0, "dense.huber_sigmas", "must be >= 0");
  require(covariance.model_scale > 0.0, "covariance.model_scale", "must be > 0");
  require(covariance.translation_floor_m >= 0.0, "covariance.translation_floor_m", "must be >= 0");
  require(covariance.rotation_floor_rad >= 0.0, "covariance.rotation_floor_rad", "must be >= 0");
  require(covariance.translation_per_rad_m >= 0.0, "covariance.translation_per_rad_m", "must be >= 0");
  require(covariance.rotation_per_rad >= 0.0, "covariance.rotation_per_rad", "must be >= 0");
  require(keyframe.min_inliers_to_keep >= 0, "keyframe.min_inliers_to_keep", "must be >= 0");
  require(keyframe.min_inlier_fraction_to_keep >= 0.0 && keyframe.min_inlier_fraction_to_keep <= 1.0,
          "keyframe.min_inlier_fraction_to_keep", "must be in [0, 1]");
  require(keyframe.min_inliers_to_keep_near >= 0, "keyframe.min_inliers_to_keep_near", "must be >= 0");
  require(keyframe.floor_cap_fraction >= 0.0 && keyframe.floor_cap_fraction <= 1.0, "keyframe.floor_cap_fraction",
          "must be in [0, 1]");
  require(keyframe.near_translation_m >= 0.0 && keyframe.near_rotation_rad >= 0.0,
          "keyframe.near_translation_m/near_rotation_rad", "must be >= 0");
  require(min_features >= 0 && min_features_with_depth >= 3 && min_matches >= 3,
          "min_features/min_features_with_depth/min_matches", "must be >= 0 / 3 / 3");
}

const char* to_string(InlierMethod m) {
  switch (m) {
    case InlierMethod::kMaxClique: return "max-clique";
    case InlierMethod::kRansac: return "ransac";
    case InlierMethod::kPreemptiveRansac: return "preemptive-ransac";
  }
  return "?";
}

const char* to_string(Solver s) {
  switch (s) {
    case Solver::kGaussNewton: return "gauss-newton";
    case Solver::kEsm: return "esm";
  }
  return "?";
}

}  // namespace kestrel::vo
