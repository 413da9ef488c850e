#pragma once
// Options of the SLAM back-end (slam.h), grouped by concern; every field has its default and
// unit. Defaults follow PAPER.md section 3 (keyframes every 10 degrees or 25 cm; loop
// candidates older than 4 s, within 90 degrees and 5 m, 15 best by appearance).

#include <cmath>

#include "common/numbers.h"
#include "slam/backend/loop_consistency.h"
#include "slam/place/frame_features.h"
#include "slam/place/loop_verifier.h"
#include "slam/place/place_recognizer.h"
#include "slam/posegraph/optimizer.h"

namespace kestrel::slam {

struct KeyframeOptions {
  double min_translation_m = 0.25;           ///< a keyframe when the camera moved this far...
  double min_rotation_rad = 10.0 * kPi / 180.0;  ///< ...or turned this much since the last
};

/// Bounded memory: where a keyframe already covers the view, a frame that moved enough to be
/// a keyframe is located against it (verified by its features, as a loop is) instead of
/// becoming one, and the odometry goes on from there (Slam::reference()). Over ground already
/// mapped nothing is added, so the keyframes (and the mapper's scans) grow with the ground
/// covered, not with the time flown.
struct CoverageOptions {
  bool reuse_keyframes = true;
  double max_translation_m = 0.25;               ///< a keyframe covers a view within this distance...
  double max_rotation_rad = 10.0 * kPi / 180.0;  ///< ...and angle of its estimated pose
  int max_candidates = 3;                        ///< covering keyframes verified, nearest first
  /// The located pose may differ from the estimate by at most this; a larger correction is a
  /// loop closure and an optimisation of the graph (below).
  double max_correction_m = 0.05;
  double max_correction_rad = 2.0 * kPi / 180.0;
  /// Such a loop closes by an edge from the covering keyframe to the reference's keyframe,
  /// through the frame (its location there and its odometry from the reference), when the pair
  /// may close a loop (LoopSearchOptions::min_age_s), the frame verifies as a loop does and the
  /// edge passes the loop gate (LoopConsistencyOptions); else, and when false, through a new
  /// keyframe. A revisit then adds no vertex: on a loop flown for half an hour, where the
  /// drift between re-anchorings exceeds the bound once a lap, each lap made a keyframe and
  /// the mapper a scan for it (docs/decisions/2026-12-07-loops-closed-without-a-keyframe.md).
  bool close_loops_in_place = true;
  /// A covered frame that no covering keyframe verifies (blur, a view the keyframes see at
  /// another scale) is carried at its predicted pose rather than made a keyframe while that
  /// prediction is certain and local: this many of its standard deviations (largest axis) lie
  /// within the correction bound above, in translation and in rotation, so that a later frame
  /// of the carried chain can still be located within the bound; and the reference's keyframe
  /// covers the frame or is an odometry neighbour of one that does, so that the prediction,
  /// relative to it, says where the frame is against the covering keyframes (a revisit after a
  /// long way round, where the world estimate may have drifted, is a keyframe and searches its
  /// loop). A keyframe there would add a view the map holds and an odometry edge the carried
  /// reference holds as well. 0: never (in mapping; localising only, every unverified covered
  /// frame is carried).
  double carry_within_sigmas = 3.0;
  /// A covered frame that no covering keyframe verifies, and whose prediction is not certain
  /// and local enough to carry (above), is carried all the same when it has fewer feature
  /// points with depth than this, rather than made a keyframe: a keyframe of it would hardly
  /// ever verify. Where covered frames verify in the simulator's rooms, a fifth to a half of
  /// their points come back as inliers; at a fifth, the verifier's 10 inliers need 50 points.
  /// A blank wall with a box's outline in view gives 13-44, mostly where an edge crosses
  /// another at a different depth, which no other view sees again
  /// (docs/decisions/2026-12-07-soak-keyframes-on-a-poor-stretch.md). 0: never.
  int min_points_to_verify = 50;
};

/// The memory bound: keyframes keep their features (keypoints, descriptors, 3-D points: what
/// loops and re-anchoring match against, ~100 kB each on the simulator's 640x480) within this budget. Over it, the
/// oldest keyframe of the fullest bin of nearby, similar views (common/geometry/view_bins.h, the
/// mapper's policy) lets its features go: it stays in the graph (its pose, its edges, the
/// mapper's scan) but is no longer matched. A place seen once keeps its only view; the newest
/// keyframe is never thinned. What remains per keyframe is the graph's vertex and edges.
struct KeyframeMemoryOptions {
  double max_megabytes = 256.0;  ///< features of all keyframes, MB (10^6 bytes)
  double bin_size_m = 0.5;       ///< thinning bins: position cell
  double bin_angle_deg = 30.0;   ///< thinning bins: optical-axis sector
};

/// A Slam started from a saved map (slam_map.h) knows nothing of where the camera is. Each frame
/// is compared by appearance with the whole map and its best keyframes are verified
/// geometrically, as a loop is (no gate by pose or age: there is no estimate yet). A false
/// place is worse than none, so one verified placement is only a hypothesis: it is accepted
/// when placements from other frames, each carried through the odometry since, put the
/// odometry frame at the same place in the map. A wrong place verified by chance is not verified
/// again, consistently, from other views; the bounds are re-anchoring's correction bounds
/// (CoverageOptions), far above the odometry's drift over max_span_s.
struct RelocalisationOptions {
  int max_candidates = 5;          ///< keyframes verified per frame, best by appearance first
  int confirmations = 2;           ///< agreeing placements from different frames (1: the first is taken)
  double max_disagreement_m = 0.05;
  double max_disagreement_rad = 2.0 * kPi / 180.0;
  double max_span_s = 2.0;         ///< placements of frames at most this far apart agree
  /// The ratio test of a placement's matching (VerificationOptions::ratio). Looser than the
  /// loops' 0.6 (Lowe's 0.8): brick and floor tiles repeat, and in a corridor of them 0.6 left 1-6
  /// matches with the right keyframe; a placement, unlike a loop, must be confirmed by another.
  double match_ratio = 0.8;
  /// Not placed this long after the first frame (a camera that starts where the map never
  /// looked): keyframes are made in a frame of their own (provisional, Slam::provisional_from()),
  /// and joined to the map, moved into its world, when a placement is confirmed. Infinite: the
  /// camera adds nothing until it is placed.
  double map_unplaced_after_s = 1.0;
};

struct LoopSearchOptions {
  double min_age_s = 4.0;       ///< candidates are keyframes at least this much older
  /// Candidates lie within this distance and angle of the current estimate; <= 0 disables the
  /// gate (for when the estimate is not trustworthy, e.g. after the odometry broke).
  double max_distance_m = 5.0;
  double max_angle_rad = kPi / 2;
  int max_candidates = 15;      ///< by appearance score, verified best first
  double min_score = 0.0;       ///< appearance score below which a candidate is not verified
};

/// Uncertainty of the odometry between consecutive keyframes. When the odometry reports its own
/// covariance (VO_UPDATE carries one; OdometryChain::relative_covariance chains it between the
/// keyframes) that is used, plus a small floor; otherwise a constant model (the paper's
/// "constant noise model fitted from data"): sigma = floor + rate * motion.
struct OdometryNoise {
  /// Use the odometry's reported covariance when there is one. The constant model below is
  /// pessimistic for a good odometry (simulator: ~20x in rotation), so that a verified loop
  /// with a few centimetres of error outweighed millimetre-accurate odometry (see README).
  bool use_reported = true;
  double reported_translation_floor_m = 0.001;  ///< added in quadrature to the reported
  double reported_rotation_floor_rad = 0.001;
  double translation_floor_m = 0.01;
  double translation_per_m = 0.05;       ///< m of error per m travelled
  double rotation_floor_rad = 0.005;
  double rotation_per_rad = 0.05;        ///< rad of error per rad turned
  double rotation_per_m = 0.02;          ///< rad of error per m travelled
  /// When the odometry broke (VO restarted) and nothing bridged the gap: a weak edge.
  double break_translation_m = 1.0;
  double break_rotation_rad = 0.5;
  /// When the state estimator bridged the gap (IMU through the VO's outage): these floors
  /// instead of translation_floor_m and rotation_floor_rad (a few seconds on the IMU alone).
  double bridge_translation_m = 0.05;
  double bridge_rotation_rad = 0.02;
};

struct SlamOptions {
  KeyframeOptions keyframes;
  CoverageOptions coverage;
  KeyframeMemoryOptions memory;
  LoopSearchOptions loops;
  RelocalisationOptions relocalisation;
  /// Localisation only (on a saved map): over the map no keyframe is added. A frame that would
  /// be one is re-anchored on the map, or carried at its predicted pose when its view does not
  /// verify (thinned keyframes still cover their views); one located beyond the correction
  /// bound is carried and the next frames are relocalised (RelocalisationOptions) instead of
  /// closing a loop, for at most max_span_s (then the estimate carries on). Where no keyframe is
  /// near (the vehicle left the map), and after a break of the odometry until a loop re-attaches
  /// it, keyframes are added as in mapping.
  bool localize_only = false;
  /// A verified loop must agree with the odometry between its keyframes (when the estimate is
  /// trustworthy): rejects perceptual aliasing (loop_consistency.h).
  LoopConsistencyOptions loop_consistency;
  OdometryNoise odometry;
  FeatureOptions features;
  PlaceOptions place;
  VerificationOptions verification;
  OptimizerOptions optimizer = default_optimizer();

  /// Dynamic covariance scaling on loop closures: a false loop that passed verification is
  /// down-weighted instead of bending the map. The chordal start is tried and kept only when it
  /// costs less than the previous solution extended by odometry (after a long loop with much
  /// drift it does).
  static OptimizerOptions default_optimizer() {
    OptimizerOptions o;
    o.kernel.type = KernelType::kDcs;
    o.kernel.width = 3.0;
    o.max_iterations = 50;
    o.function_tolerance = 1e-4;
    return o;
  }
};

}  // namespace kestrel::slam
