#pragma once
// Options of the visual odometry: one small struct per stage, every field with its default and
// unit. `VoOptions{}` is kestrel's pipeline as measured in vo/README.md; vo/variants.h derives
// the paper's Table 1 variants from it by changing one stage at a time.
//
// Invariant: validate() accepts every combination the variants produce and rejects, naming the
// field, any value a stage cannot run with.

#include <string>

#include "sensors/depth_image.h"

namespace kestrel::vo {

/// Grey image, Gaussian blur and pyramid (one octave per level).
struct PyramidOptions {
  int levels = 3;             ///< feature pyramid levels, 1..4
  double blur_sigma = 0.85;   ///< Gaussian blur of level 0, pixels (0 = none)
};

/// FAST-9 detection on every level and its adaptive threshold.
struct FastOptions {
  int threshold = 20;                 ///< initial (or fixed) intensity threshold, grey levels
  bool adaptive = true;               ///< proportional controller on the number of detections
  double target_pixels_per_feature = 250.0;  ///< target detections = width*height / this
  double adaptive_gain = 0.005;       ///< threshold change per surplus detection
  int min_threshold = 5;
  int max_threshold = 70;
};

/// Keeps the strongest features of each image cell so that they spread over the image.
struct BucketOptions {
  bool enabled = true;
  int width_px = 80;          ///< bucket size in the level's pixels
  int height_px = 80;
  int max_per_bucket = 25;
};

/// Depth at a feature, its uncertainty, and the RGB/depth time offset.
struct DepthOptions {
  double min_m = 0.3;                   ///< closer readings are dropped (Kinect minimum range)
  double max_m = 6.0;                   ///< farther readings are dropped
  double max_discontinuity = 0.05;      ///< drop a feature whose 3x3 depth spread exceeds this fraction of its depth
  double sigma_z_coeff = 1.4e-3;        ///< depth noise sigma_z = coeff * z^2 (metres; Khoshelham 2011)
  bool compensate_time_offset = false;  ///< look depth up where the point was at depth time
  /// The offset compensated (depth capture minus colour capture time) is the frame's depth
  /// stamp minus its RGB stamp plus time_offset_s: for a source whose stamps are arrival
  /// times, time_offset_s is minus the depth image's extra latency (a Kinect:
  /// with_sensor()). When false, time_offset_s alone, whatever the stamps say.
  bool time_offset_from_stamps = true;
  double time_offset_s = 0.0;           ///< seconds
  bool undistort = true;                ///< use the camera's lens distortion for rays and reprojection
  /// Colour rolling shutter, first-to-last row time; 0 = global shutter (the simulator's camera).
  /// A freiburg1 TUM run uses the Kinect's (with_tum_sensor(), vo/sequence_run.h).
  double rolling_shutter_readout_s = 0.0;

  sensors::DepthValidity validity() const { return {min_m, max_m, max_discontinuity}; }
  sensors::DepthTiming timing() const { return {time_offset_from_stamps, time_offset_s}; }
};

/// Initial rotation by aligning heavily down-sampled images (Mei et al.).
struct RotationPriorOptions {
  bool enabled = true;
  int downsample_level = 4;   ///< image of 1/2^level the size (4: 40 x 30 for VGA)
  int max_iterations = 12;
  bool predict_from_velocity = true;  ///< start from the previous frame-to-frame rotation
};

/// Patch descriptors, windowed matching and subpixel refinement.
struct MatchOptions {
  int window_size = 9;          ///< descriptor patch side, odd, 3..11 (9: 80 bytes)
  double search_radius_px = 20.0;  ///< around the predicted position, level-0 pixels
  int max_sad_per_pixel = 40;   ///< reject a match whose mean absolute difference is larger
  bool subpixel = true;         ///< refine each match to subpixel precision
  double max_subpixel_shift_px = 1.5;  ///< a refinement moving farther is rejected (level pixels)
};

enum class InlierMethod { kMaxClique, kRansac, kPreemptiveRansac };

/// Inlier detection among the matches.
struct InlierOptions {
  InlierMethod method = InlierMethod::kMaxClique;
  double clique_threshold_m = 0.04;   ///< floor on the distance-preservation tolerance, metres
  double clique_sigmas = 3.0;         ///< tolerance in depth-noise standard deviations
  int ransac_hypotheses = 500;
  double ransac_threshold_m = 0.03;   ///< 3D distance for a RANSAC inlier
  int ransac_block_size = 100;        ///< preemptive RANSAC: observations scored per round
  int min_inliers = 10;
};

enum class Solver { kGaussNewton, kEsm };

/// Motion from the inliers: Horn, then non-linear reprojection refinement.
struct RefinementOptions {
  bool enabled = true;            ///< false: absolute orientation only
  Solver solver = Solver::kEsm;
  bool bidirectional = true;
  bool depth_weighted = true;     ///< whiten residuals by the projected depth noise
  bool depth_residuals = true;    ///< also compare the two depths of each match along its ray
  double depth_sigma_floor_mm = 1.0;  ///< added in quadrature to the depth noise of a depth residual
  double pixel_sigma = 1.2;       ///< measurement noise of a feature position, pixels (weighting)
  /// The reported information takes the pixel noise from the final residuals (their spread
  /// across the depth direction) instead of pixel_sigma; the weighting keeps pixel_sigma.
  bool pixel_sigma_from_residuals = true;
  double min_pixel_sigma = 0.05;  ///< floor on that estimate, pixels (subpixel resolution)
  double huber_px = 1.5;          ///< robust loss threshold on a whitened residual (sigmas); 0 = none
  double outlier_threshold_px = 2.0;   ///< residuals above this (pixels) are dropped before re-refining
  int max_iterations = 4;         ///< 5 until the dense term: 4 is within 0.5 % on every figure and ~0.1 ms faster
  int min_inliers = 10;           ///< fewer after outlier removal = optimisation failure
};

/// Dense geometric term of the final refinement: point-to-plane residuals of the current frame's
/// depth (a coarse grid) against the reference's depth and normals, by projective association,
/// whitened by the depth noise, robust, jointly with the feature residuals.
struct DenseOptions {
  bool enabled = true;
  int level = 3;                  ///< grid of 1/2^level of the image (3: 80 x 60 for VGA)
  int stride = 2;                 ///< every stride-th cell of the current grid, each direction
  double weight = 0.4;            ///< multiplies the information of each dense residual
  double max_distance_m = 0.05;   ///< association gate on the point distance
  double max_normal_angle_deg = 30.0;  ///< association gate on the normals' angle
  double sigma_floor_mm = 1.0;    ///< added in quadrature to the depth noise of a residual
  double huber_sigmas = 1.5;      ///< robust loss threshold on a whitened residual; 0 = none
};

/// What the reported covariance adds to the refinement's own (whose noise model only holds
/// independent pixel and depth noise): the error the model does not contain, a property of
/// the sensor, in two parts that behave differently along a chain of motions:
///  * floors: noise of each frame's pose (misregistration, a frame's own timing), the same
///    for every motion; between consecutive motions it cancels, so a chain counts it once
///    (VoResult's floors, slam's OdometryChain);
///  * a part proportional to the motion's rotation angle (timing and rolling-shutter errors
///    scale with how far the camera turned), which is the motion's own and adds up.
/// The defaults are the simulator's camera (global shutter, one capture time; its errors are
/// correlated over a frame: depth quantised on whole surfaces, rendering), fitted so the mean
/// NEES is near 6 on the room figure-eight and checked on two other flights (vo/README.md,
/// "Covariance"); a Kinect's are larger (sensors/profiles/kinect1.yaml).
struct CovarianceOptions {
  double model_scale = 1.0;              ///< multiplies the refinement's covariance
  double translation_floor_m = 0.0006;   ///< per-axis sigma added in quadrature, metres
  double rotation_floor_rad = 0.0002;    ///< per-axis sigma added in quadrature, radians
  double translation_per_rad_m = 0.0;    ///< per-axis sigma per radian of the motion's rotation, metres
  double rotation_per_rad = 0.0;         ///< per-axis sigma per radian of the motion's rotation, radians
};

/// Reference (key) frame policy.
struct KeyframeOptions {
  /// Absolute floor: below this many reprojection inliers the current frame becomes the reference.
  int min_inliers_to_keep = 300;
  /// Relative rule: the current frame also becomes the reference when its inliers fall below this
  /// fraction of the keyframe's inliers at its first match (0 = off, only the floor applies).
  double min_inlier_fraction_to_keep = 0.0;
  /// Near rule: while the camera is within near_translation_m and near_rotation_rad of the
  /// keyframe, the keyframe is kept down to min_inliers_to_keep_near instead (0 = off). A
  /// hovering camera stays near its keyframe, often with fewer than min_inliers_to_keep
  /// inliers in view; re-keying it at every frame turns a bounded error into a random walk
  /// (vo/README.md, "Keyframes"). 150 is fovis's own re-keying threshold.
  int min_inliers_to_keep_near = 150;
  double near_translation_m = 0.03;
  double near_rotation_rad = 0.03;
  /// Poor-scene cap (0 = off): the floors above never exceed this fraction of the keyframe's
  /// inliers at its first match. Where a scene offers fewer inliers than the floors (a bare
  /// corridor: 80-110), they would re-key at every frame and the pose becomes a random walk of
  /// frame-to-frame errors; capped, the keyframe is kept while it still holds this share of
  /// what it first matched. In a scene rich enough (first match >= floor / fraction) the
  /// floors apply unchanged. A keyframe's first match is never below the cap, so a frame that
  /// becomes the reference with few inliers is held all the same. On the simulator's camera
  /// 0.7 makes the VO alone 3-6x more accurate on stata's survey flights (1.1x on its loops);
  /// fr1 (Kinect) is best without it. With the estimator's keyframe share (7 Dec) the stata
  /// BRM flights stay within 0.3 m on 10 of 12 with it (11 at 95ea46f), 7 of 12 without. Off here, on in the
  /// simulator's profile (sensors/profiles/simulator.yaml): a camera without a profile keeps
  /// the default, which fr1 says is better for a Kinect
  /// (docs/decisions/2026-12-07-estimator-keyframe-share.md).
  double floor_cap_fraction = 0.0;
  bool fall_back_to_previous = true;
};

struct VoOptions {
  PyramidOptions pyramid;
  FastOptions fast;
  BucketOptions bucket;
  DepthOptions depth;
  RotationPriorOptions rotation_prior;
  MatchOptions match;
  InlierOptions inliers;
  RefinementOptions refinement;
  DenseOptions dense;
  CovarianceOptions covariance;
  KeyframeOptions keyframe;
  int min_features = 30;          ///< fewer detections: "too few features"
  int min_features_with_depth = 20;  ///< fewer with valid depth: "too little valid depth"
  int min_matches = 15;            ///< fewer mutual matches: "too few matches"

  /// Throws std::invalid_argument naming the first unusable field.
  void validate() const;
};

const char* to_string(InlierMethod m);
const char* to_string(Solver s);

}  // namespace kestrel::vo
