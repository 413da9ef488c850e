#include "vo/option_keys.h"

#include <sstream>
#include <stdexcept>
#include <variant>

namespace kestrel::vo {
namespace {

using Field = std::variant<bool*, int*, double*, InlierMethod*, Solver*>;

std::vector<std::pair<std::string, Field>> fields(VoOptions& o) {
  return {
      {"pyramid.levels", &o.pyramid.levels},
      {"pyramid.blur_sigma", &o.pyramid.blur_sigma},
      {"fast.threshold", &o.fast.threshold},
      {"fast.adaptive", &o.fast.adaptive},
      {"fast.target_pixels_per_feature", &o.fast.target_pixels_per_feature},
      {"fast.adaptive_gain", &o.fast.adaptive_gain},
      {"fast.min_threshold", &o.fast.min_threshold},
      {"fast.max_threshold", &o.fast.max_threshold},
      {"bucket.enabled", &o.bucket.enabled},
      {"bucket.width_px", &o.bucket.width_px},
      {"bucket.height_px", &o.bucket.height_px},
      {"bucket.max_per_bucket", &o.bucket.max_per_bucket},
      {"depth.min_m", &o.depth.min_m},
      {"depth.max_m", &o.depth.max_m},
      {"depth.max_discontinuity", &o.depth.max_discontinuity},
      {"depth.sigma_z_coeff", &o.depth.sigma_z_coeff},
      {"depth.compensate_time_offset", &o.depth.compensate_time_offset},
      {"depth.time_offset_from_stamps", &o.depth.time_offset_from_stamps},
      {"depth.time_offset_s", &o.depth.time_offset_s},
      {"depth.undistort", &o.depth.undistort},
      {"depth.rolling_shutter_readout_s", &o.depth.rolling_shutter_readout_s},
      {"rotation_prior.enabled", &o.rotation_prior.enabled},
      {"rotation_prior.downsample_level", &o.rotation_prior.downsample_level},
      {"rotation_prior.max_iterations", &o.rotation_prior.max_iterations},
      {"rotation_prior.predict_from_velocity", &o.rotation_prior.predict_from_velocity},
      {"match.window_size", &o.match.window_size},
      {"match.search_radius_px", &o.match.search_radius_px},
      {"match.max_sad_per_pixel", &o.match.max_sad_per_pixel},
      {"match.subpixel", &o.match.subpixel},
      {"match.max_subpixel_shift_px", &o.match.max_subpixel_shift_px},
      {"inliers.method", &o.inliers.method},
      {"inliers.clique_threshold_m", &o.inliers.clique_threshold_m},
      {"inliers.clique_sigmas", &o.inliers.clique_sigmas},
      {"inliers.ransac_hypotheses", &o.inliers.ransac_hypotheses},
      {"inliers.ransac_threshold_m", &o.inliers.ransac_threshold_m},
      {"inliers.ransac_block_size", &o.inliers.ransac_block_size},
      {"inliers.min_inliers", &o.inliers.min_inliers},
      {"refinement.enabled", &o.refinement.enabled},
      {"refinement.solver", &o.refinement.solver},
      {"refinement.bidirectional", &o.refinement.bidirectional},
      {"refinement.depth_weighted", &o.refinement.depth_weighted},
      {"refinement.depth_residuals", &o.refinement.depth_residuals},
      {"refinement.depth_sigma_floor_mm", &o.refinement.depth_sigma_floor_mm},
      {"refinement.pixel_sigma", &o.refinement.pixel_sigma},
      {"refinement.pixel_sigma_from_residuals", &o.refinement.pixel_sigma_from_residuals},
      {"refinement.min_pixel_sigma", &o.refinement.min_pixel_sigma},
      {"refinement.huber_px", &o.refinement.huber_px},
      {"refinement.outlier_threshold_px", &o.refinement.outlier_threshold_px},
      {"refinement.max_iterations", &o.refinement.max_iterations},
      {"refinement.min_inliers", &o.refinement.min_inliers},
      {"dense.enabled", &o.dense.enabled},
      {"dense.level", &o.dense.level},
      {"dense.stride", &o.dense.stride},
      {"dense.weight", &o.dense.weight},
      {"dense.max_distance_m", &o.dense.max_distance_m},
      {"dense.max_normal_angle_deg", &o.dense.max_normal_angle_deg},
      {"dense.sigma_floor_mm", &o.dense.sigma_floor_mm},
      {"dense.huber_sigmas", &o.dense.huber_sigmas},
      {"covariance.model_scale", &o.covariance.model_scale},
      {"covariance.translation_floor_m", &o.covariance.translation_floor_m},
      {"covariance.rotation_floor_rad", &o.covariance.rotation_floor_rad},
      {"covariance.translation_per_rad_m", &o.covariance.translation_per_rad_m},
      {"covariance.rotation_per_rad", &o.covariance.rotation_per_rad},
      {"keyframe.min_inliers_to_keep", &o.keyframe.min_inliers_to_keep},
      {"keyframe.min_inlier_fraction_to_keep", &o.keyframe.min_inlier_fraction_to_keep},
      {"keyframe.min_inliers_to_keep_near", &o.keyframe.min_inliers_to_keep_near},
      {"keyframe.near_translation_m", &o.keyframe.near_translation_m},
      {"keyframe.near_rotation_rad", &o.keyframe.near_rotation_rad},
      {"keyframe.floor_cap_fraction", &o.keyframe.floor_cap_fraction},
      {"keyframe.fall_back_to_previous", &o.keyframe.fall_back_to_previous},
      {"min_features", &o.min_features},
      {"min_features_with_depth", &o.min_features_with_depth},
      {"min_matches", &o.min_matches},
  };
}

template <class T>
T parse_number(const std::string& key, const std::string& text) {
  std::istringstream in(text);
  T v{};
  in >> v;
  if (!in || !in.eof()) throw std::invalid_argument("vo option " + key + ": '" + text + "' is not a number");
  return v;
}

struct Assign {
  const std::string& key;
  const std::string& text;
  void operator()(bool* p) const {
    if (text == "true" || text == "1") *p = true;
    else if (text == "false" || text == "0") *p = false;
    else throw std::invalid_argument("vo option " + key + ": '" + text + "' is not true/false");
  }
  void operator()(int* p) const { *p = parse_number<int>(key, text); }
  void operator()(double* p) const { *p = parse_number<double>(key, text); }
  void operator()(InlierMethod* p) const {
    for (InlierMethod m : {InlierMethod::kMaxClique, InlierMethod::kRansac, InlierMethod::kPreemptiveRansac})
      if (text == to_string(m)) return void(*p = m);
    throw std::invalid_argument("vo option " + key + ": '" + text + "' is not max-clique/ransac/preemptive-ransac");
  }
  void operator()(Solver* p) const {
    for (Solver s : {Solver::kGaussNewton, Solver::kEsm})
      if (text == to_string(s)) return void(*p = s);
    throw std::invalid_argument("vo option " + key + ": '" + text + "' is not gauss-newton/esm");
  }
};

struct Print {
  std::string operator()(bool* p) const { return *p ? "true" : "false"; }
  std::string operator()(int* p) const { return std::to_string(*p); }
  std::string operator()(double* p) const {
    std::ostringstream out;
    out << *p;
    return out.str();
  }
  std::string operator()(InlierMethod* p) const { return to_string(*p); }
  std::string operator()(Solver* p) const { return to_string(*p); }
};

}  // namespace

void set_option(VoOptions& options, const std::string& key, const std::string& value) {
  VoOptions changed = options;
  for (auto& [name, field] : fields(changed)) {
    if (name != key) continue;
    std::visit(Assign{key, value}, field);
    changed.validate();
    options = changed;
    return;
  }
  throw std::invalid_argument("unknown vo option '" + key + "'");
}

void set_option_assignment(VoOptions& options, const std::string& kv) {
  const size_t eq = kv.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("'" + kv + "' is not KEY=VALUE");
  set_option(options, kv.substr(0, eq), kv.substr(eq + 1));
}

std::vector<std::string> describe_options(const VoOptions& options) {
  VoOptions copy = options;
  std::vector<std::string> out;
  for (auto& [name, field] : fields(copy)) out.push_back(name + " = " + std::visit(Print{}, field));
  return out;
}

}  // namespace kestrel::vo
