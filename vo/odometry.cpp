#include "vo/odometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/geometry/so3.h"
#include "sensors/lens.h"
#include "vo/depth_lookup.h"
#include "vo/feature_detector.h"
#include "vo/frame.h"
#include "vo/matcher.h"
#include "vo/motion_estimator.h"
#include "vo/rotation_prior.h"

namespace kestrel::vo {
namespace {

// A rotation prior farther than this from the velocity prediction is taken as a failed alignment.
constexpr double kMaxPriorDisagreementRad = 0.35;

std::string counts(const char* what, int have, int need) {
  return std::string(what) + ": " + std::to_string(have) + " (need " + std::to_string(need) + ")";
}

void build_coarse(const ImagePyramid& pyramid, int level, cv::Mat& coarse, cv::Mat& scratch,
                  std::vector<uint16_t>& row) {
  const int top = pyramid.levels() - 1;
  if (level <= top) {
    pyramid.level(level).copyTo(coarse);
    return;
  }
  const cv::Mat* from = &pyramid.level(top);
  for (int l = top + 1; l <= level; ++l) {
    cv::Mat& to = (level - l) % 2 == 0 ? coarse : scratch;  // the last one lands in `coarse`
    half_size(*from, to, row);
    from = &to;
  }
}

}  // namespace

// The odometry itself; VisualOdometry forwards to it.
class VisualOdometry::Pipeline {
 public:
  explicit Pipeline(const VoOptions& options);
  VoResult process(const RgbdFrame& input);
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

VisualOdometry::Pipeline::Pipeline(const VoOptions& options)
    : options_(options),
      threshold_(options.fast),
      detector_(options.pyramid, options.bucket, options.match) {
  options_.validate();
  for (auto& f : pool_) f = std::make_unique<Frame>();
}

void VisualOdometry::Pipeline::reset() {
  keyframe_ = nullptr;
  keyframe_first_inliers_ = 0;
  previous_ = nullptr;
  T_key_prev_.setIdentity();
  T_prev_cur_last_.setIdentity();
  have_velocity_ = false;
  last_dt_s_ = 0.0;
  consecutive_failures_ = 0;
  last_utime_ = 0;
  threshold_.reset();
}

Frame* VisualOdometry::Pipeline::acquire_frame() {
  for (auto& f : pool_)
    if (f.get() != keyframe_ && f.get() != previous_) return f.get();
  throw std::logic_error("VisualOdometry: frame pool exhausted");  // cannot happen with 3 frames
}

std::string VisualOdometry::Pipeline::check_input(const RgbdFrame& frame) const {
  if (frame.rgb.empty()) return "frame has no colour image";
  if (frame.depth_mm.empty()) return "frame has no depth image";
  try {
    frame.validate("frame");
  } catch (const InputError& e) {
    return e.what();
  }
  if (!frame.T_body_camera.matrix().allFinite()) return "frame: non-finite camera mounting";
  if (frame.camera.width < 32 || frame.camera.height < 32) return "frame: image smaller than 32x32";
  if (last_utime_ != 0 && frame.utime <= last_utime_) {
    return "frame: time stamp " + std::to_string(frame.utime) + " is not after the previous frame's " +
           std::to_string(last_utime_);
  }
  return {};
}

Eigen::Isometry3d VisualOdometry::Pipeline::predict_prev_cur(const Frame& cur) {
  const double dt = 1e-6 * double(cur.utime - previous_->utime);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (have_velocity_ && last_dt_s_ > 0.0) T = se3::exp(se3::log(T_prev_cur_last_) * (dt / last_dt_s_));
  const RotationPriorOptions& rp = options_.rotation_prior;
  if (!rp.enabled) return T;
  const Eigen::Matrix3d R_init =
      rp.predict_from_velocity ? Eigen::Matrix3d(T.linear().transpose()) : Eigen::Matrix3d::Identity();
  const PinholeCamera coarse_camera = lens_.camera().scaled(1.0 / double(1 << rp.downsample_level));
  const RotationPriorResult prior =
      rotation_prior_.estimate(previous_->coarse, cur.coarse, coarse_camera, R_init, rp.max_iterations);
  if (prior.iterations > 0 && so3::angle(prior.R_cur_prev * T.linear()) < kMaxPriorDisagreementRad)
    T.linear() = prior.R_cur_prev.transpose();
  return T;
}

VisualOdometry::Pipeline::Attempt VisualOdometry::Pipeline::estimate_against(const Frame& ref, const Frame& cur,
                                                         const Eigen::Isometry3d& T_ref_cur_predicted) {
  const Eigen::Isometry3f T_cur_ref = T_ref_cur_predicted.inverse().cast<float>();
  const PinholeCamera& cam = lens_.camera();
  predicted_.resize(ref.features.size());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < ref.features.size(); ++i) {
    const Feature& f = ref.features[i];
    const Eigen::Vector3f X = T_cur_ref * f.p_camera;
    if (X.z() < 0.05f) {
      predicted_[i] = Eigen::Vector2f(nan, nan);
      continue;
    }
    const Eigen::Vector2f ideal(float(cam.fx) * X.x() / X.z() + float(cam.cx),
                                float(cam.fy) * X.y() / X.z() + float(cam.cy));
    // The lens distortion barely changes over a matching window: carry the reference's offset.
    predicted_[i] = ideal + (Eigen::Vector2f(f.u0, f.v0) - f.ideal);
  }
  matcher_.match(ref, cur, predicted_, lens_, options_.match, matches_);
  Attempt a;
  a.reference = &ref;
  const uint64_t seed = static_cast<uint64_t>(cur.utime) * 2654435761u ^ static_cast<uint64_t>(ref.utime);
  a.estimate = estimator_.estimate(ref, cur, matches_, lens_, options_, seed);
  return a;
}

VoResult VisualOdometry::Pipeline::process(const RgbdFrame& input) {
  VoResult result;
  result.utime = input.utime;
  result.seq = input.seq;
  result.previous_utime = previous_ != nullptr ? previous_->utime : 0;
  result.fast_threshold = threshold_.threshold();

  const std::string bad = check_input(input);
  if (!bad.empty()) {
    result.status = VoStatus::kBadInput;
    result.message = bad;
    return result;
  }
  if (!lens_.prepared_for(input.camera, options_.depth.undistort)) {
    const bool had_reference = keyframe_ != nullptr;
    reset();
    lens_.reset(input.camera, options_.depth.undistort);
    if (had_reference) result.message = "camera changed: odometry restarted";
    result.previous_utime = 0;
  }
  last_utime_ = input.utime;

  Frame& cur = *acquire_frame();
  cur.utime = input.utime;
  cur.depth_utime = input.depth_utime;
  cur.seq = input.seq;
  detector_.detect(input.rgb, threshold_.threshold(), cur);
  threshold_.update(cur.num_detected, input.camera.width * input.camera.height);
  result.num_features = cur.num_detected;
  if (cur.num_detected < options_.min_features) {
    // A blank view counts as a failure, so that the first frame with features again restarts
    // the odometry at once if it cannot be matched to the reference from before the gap.
    ++consecutive_failures_;
    result.status = VoStatus::kInsufficientFeatures;
    result.message = counts("too few features", cur.num_detected, options_.min_features);
    return result;
  }
  build_coarse(cur.pyramid, options_.rotation_prior.downsample_level, cur.coarse, coarse_scratch_,
               coarse_row_);

  // The motion since the previous frame, predicted; it also carries depth to RGB time.
  Eigen::Isometry3d T_prev_cur_predicted = Eigen::Isometry3d::Identity();
  if (previous_ != nullptr) T_prev_cur_predicted = predict_prev_cur(cur);
  sensors::FrameMotion motion;
  if (previous_ != nullptr) {
    const double dt = 1e-6 * double(cur.utime - previous_->utime);
    motion.known = dt > 0.0;
    motion.twist_per_s = se3::log(T_prev_cur_predicted) / dt;
    motion.depth_offset_s = sensors::depth_time_offset_s(options_.depth.timing(), input.utime, input.depth_utime);
    motion.readout_s = options_.depth.rolling_shutter_readout_s;
  }
  cur.motion = motion;
  attach_depth(input.depth_mm, lens_, options_.depth, motion, cur);
  result.num_features_with_depth = static_cast<int>(cur.features.size());
  if (result.num_features_with_depth < options_.min_features_with_depth) {
    ++consecutive_failures_;
    result.status = VoStatus::kInsufficientDepth;
    result.message = counts("too little valid depth: features with depth",
                            result.num_features_with_depth, options_.min_features_with_depth);
    return result;
  }
  if (options_.dense.enabled)
    build_dense_depth(input.depth_mm, lens_, options_.depth, options_.dense.level, cur.dense);
  describe_features(cur, options_.match.window_size, static_cast<float>(options_.match.search_radius_px));

  if (keyframe_ == nullptr) {
    keyframe_ = previous_ = &cur;
    keyframe_first_inliers_ = 0;
    T_key_prev_.setIdentity();
    have_velocity_ = false;
    result.status = VoStatus::kNoReference;
    result.new_reference = true;
    result.message = "first frame: it becomes the reference";
    return result;
  }

  Attempt attempt = estimate_against(*keyframe_, cur, T_key_prev_ * T_prev_cur_predicted);
  if (attempt.estimate.status != VoStatus::kOk && keyframe_ != previous_ &&
      options_.keyframe.fall_back_to_previous) {
    Attempt fallback = estimate_against(*previous_, cur, T_prev_cur_predicted);
    if (fallback.estimate.status == VoStatus::kOk) {
      attempt = fallback;
      result.fell_back_to_previous = true;
    }
  }
  const MotionEstimate& e = attempt.estimate;
  result.status = e.status;
  result.num_matches = e.num_matches;
  result.num_inliers = e.num_inliers;
  result.num_reprojection_inliers = e.num_reprojection_inliers;
  result.mean_reprojection_error_px = e.mean_reprojection_error_px;
  result.pixel_sigma_px = e.pixel_sigma_px;
  const double dt = 1e-6 * double(cur.utime - previous_->utime);

  if (e.status != VoStatus::kOk) {
    switch (e.status) {
      case VoStatus::kInsufficientMatches:
        result.message = counts("too few matches", e.num_matches, options_.min_matches);
        break;
      case VoStatus::kInsufficientInliers:
        result.message = counts("too few inliers", e.num_inliers, options_.inliers.min_inliers) +
                         " of " + std::to_string(e.num_matches) + " matches";
        break;
      default:
        result.message = counts("optimisation failure: reprojection inliers",
                                e.num_reprojection_inliers, options_.refinement.min_inliers) +
                         " of " + std::to_string(e.num_inliers) + " inliers";
    }
    if (++consecutive_failures_ >= 2) {
      // Lost: start again from this frame rather than wait for a view of the old reference.
      keyframe_ = previous_ = &cur;
      keyframe_first_inliers_ = 0;
      T_key_prev_.setIdentity();
      have_velocity_ = false;
      consecutive_failures_ = 0;
      result.new_reference = true;
      result.message += "; odometry restarted from this frame";
    }
    return result;
  }

  consecutive_failures_ = 0;
  result.reference_utime = attempt.reference->utime;
  result.T_reference_current = e.T_ref_cur;
  result.covariance = e.covariance;
  result.translation_floor_m = options_.covariance.translation_floor_m;
  result.rotation_floor_rad = options_.covariance.rotation_floor_rad;
  const bool against_previous = attempt.reference == previous_;
  T_prev_cur_last_ = against_previous ? e.T_ref_cur : Eigen::Isometry3d(T_key_prev_.inverse() * e.T_ref_cur);
  last_dt_s_ = dt;
  have_velocity_ = dt > 0.0;
  const bool against_keyframe = attempt.reference == keyframe_;
  if (against_keyframe && keyframe_first_inliers_ == 0) keyframe_first_inliers_ = e.num_reprojection_inliers;
  const double relative_floor = options_.keyframe.min_inlier_fraction_to_keep * keyframe_first_inliers_;
  const KeyframeOptions& k = options_.keyframe;
  const bool near_keyframe = against_keyframe && k.min_inliers_to_keep_near > 0 &&
                             e.T_ref_cur.translation().norm() <= k.near_translation_m &&
                             so3::angle(e.T_ref_cur.linear()) <= k.near_rotation_rad;
  double absolute_floor = near_keyframe ? std::min(k.min_inliers_to_keep_near, k.min_inliers_to_keep)
                                        : k.min_inliers_to_keep;
  if (k.floor_cap_fraction > 0.0 && keyframe_first_inliers_ > 0)
    absolute_floor = std::min(absolute_floor, k.floor_cap_fraction * keyframe_first_inliers_);
  if (result.fell_back_to_previous || e.num_reprojection_inliers < absolute_floor ||
      e.num_reprojection_inliers < relative_floor) {
    keyframe_ = &cur;
    keyframe_first_inliers_ = 0;
    T_key_prev_.setIdentity();
    result.new_reference = true;
  } else {
    T_key_prev_ = e.T_ref_cur;  // estimated against the keyframe (a fall-back always re-keys)
  }
  previous_ = &cur;
  return result;
}

VisualOdometry::VisualOdometry(const VoOptions& options) : pipeline_(std::make_unique<Pipeline>(options)) {}
VisualOdometry::~VisualOdometry() = default;
VisualOdometry::VisualOdometry(VisualOdometry&&) noexcept = default;
VisualOdometry& VisualOdometry::operator=(VisualOdometry&&) noexcept = default;

VoResult VisualOdometry::process(const RgbdFrame& frame) { return pipeline_->process(frame); }
void VisualOdometry::reset() { pipeline_->reset(); }
const VoOptions& VisualOdometry::options() const { return pipeline_->options(); }

}  // namespace kestrel::vo
