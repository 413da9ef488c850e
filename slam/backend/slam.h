#pragma once
// The SLAM back-end (PAPER.md section 3): frames with their odometry poses in; keyframes,
// verified loop closures and an optimised pose graph of the keyframes out. LCM-free: the
// process (slam/main.cpp) and the offline tools feed it.
//
// Frames: the odometry pose T_odom_camera of every frame (VO chained, odometry_chain.h). A
// frame becomes a keyframe when it moved or turned enough since the last keyframe; only then
// are its image features needed (wants_keyframe() lets a caller skip decoding the rest).
// Loop closure: the new keyframe is compared by appearance with older keyframes near its
// estimated pose; the best candidates are verified geometrically, best first, and the first
// that passes adds a loop-closure edge and the graph is optimised.
//
// Covered ground (CoverageOptions): a frame that would be a keyframe where an older keyframe
// already sees the same view, and whose features place it in that keyframe within a small
// correction of its estimate, becomes the odometry's reference instead of a keyframe
// (re-anchoring): later frames and the next keyframe's edge are measured from it. One with too
// few features ever to be located (a blank wall) becomes the reference at its predicted pose:
// a keyframe there could never be matched, and the covering one holds the view.
//
// Bounded memory (KeyframeMemoryOptions): over a budget, the keyframes of places seen from many
// similar views let their features go (thinned); they stay in the graph, unmatched.
//
// Frames: "world" is the odometry frame of the first keyframe, so before any loop closure the
// optimised poses equal the odometry poses, until change_world() moves the whole graph into
// another frame (the process puts it in the state estimator's world, slam_adapter.h). Started
// from a saved map (slam_map.h), "world" is the map's: the first frames are relocalised in it
// (RelocalisationOptions), and the camera's odometry joins the map there, as at a re-anchoring.
// A camera not placed soon (it started where the map never looked) maps in a provisional frame
// of its own meanwhile; the placement moves those keyframes into the map's world and joins them
// to it by one edge (a session that joins the map): one graph afterwards.
// Invariants: keyframe k is vertex k of graph(); vertex 0 is fixed; the edge into keyframe
// k > 0 from its reference (the previous keyframe, or the keyframe re-anchored on before it)
// is odometry, but for the first provisional keyframe, which has none; provisional keyframes
// are the newest ones (ids from provisional_from()) and no edge joins them to the others until
// the placement does; revision() grows by one with every change of the optimised poses other
// than appending a keyframe.

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include "common/geometry/view_bins.h"
#include "slam/backend/slam_map.h"
#include "common/rgbd_frame.h"
#include "sensors/sensor_profile.h"
#include "slam/backend/slam_options.h"
#include "slam/posegraph/pose_graph.h"
#include "sensors/frame_motion.h"

namespace kestrel::slam {

/// What the odometry since is measured from: the newest keyframe, or a later frame located in
/// a covering keyframe (CoverageOptions).
struct OdometryReference {
  int64_t keyframe_id = -1;
  int64_t utime = 0;                                          ///< the frame's
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();  ///< the frame's odometry pose
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// The frame in the keyframe (identity: the keyframe itself), and its covariance (right
  /// perturbation [rho; phi]; zero for the keyframe itself).
  Eigen::Isometry3d T_keyframe_camera = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();
  /// The weakest link the odometry crossed from the keyframe to the frame (a carried
  /// reference may have crossed a bridged restart): the next keyframe's edge is that weak.
  OdometryLink link = OdometryLink::kContinuous;
};

/// What one call of Slam::add did.
struct SlamStep {
  bool keyframe = false;          ///< the frame became a keyframe
  int64_t keyframe_id = -1;
  bool reanchored = false;        ///< instead, it was located in a covering keyframe...
  int64_t reanchor_keyframe_id = -1;  ///< ...this one (`loop` holds the constraint)
  /// Or, over covered ground but with too few features ever to be located, or with none of the
  /// covering keyframes verifying a certain prediction (CoverageOptions::carry_within_sigmas), it
  /// became the reference at its predicted pose (nothing measured: no correction to send).
  bool carried = false;
  /// Or, started from a saved map, the frame placed the camera in it (Slam::relocalisation());
  /// or, localising only, a confirmed placement moved it beyond the correction bound.
  /// `reanchor_keyframe_id` and `loop` say where.
  bool relocalised = false;
  int candidates = 0;             ///< loop candidates verified
  int inconsistent = 0;           ///< of them, verified but refused as disagreeing with the odometry
  /// A loop closed: the new keyframe's with an earlier one; or, over covered ground, without a
  /// keyframe (CoverageOptions::close_loops_in_place): an edge from the keyframe that located the
  /// frame beyond the correction bound to the reference's keyframe before this frame, the frame
  /// then re-anchored or carried.
  bool loop_closed = false;
  int64_t loop_keyframe_id = -1;  ///< the keyframe it closed with (older than the frame by LoopSearchOptions::min_age_s)
  LoopConstraint loop;            ///< the accepted constraint, or the last rejection
  std::optional<OptimizerSummary> optimisation;  ///< when the graph was optimised
  /// Later frames are measured from this one (Slam::reference()).
  bool new_reference() const { return keyframe || reanchored || carried || relocalised; }
};

/// Information (pose-graph error convention, spaces.h) of the odometry edge previous -> current
/// keyframe with motion T_prev_cur: from the odometry's reported covariance of that motion (a
/// right perturbation [rho; phi]) plus the noise's small floors, when there is one, the link is
/// continuous and noise.use_reported; else the constant model (break/bridge values as `link` says).
Matrix6d odometry_edge_information(const Eigen::Isometry3d& T_prev_cur, const OdometryNoise& noise, OdometryLink link,
                                   const std::optional<Matrix6d>& reported_covariance = std::nullopt);

/// Where a Slam started from a saved map found the camera.
struct Relocalisation {
  int64_t utime = 0;          ///< the frame that confirmed the place
  int frames_tried = 0;       ///< frames compared with the map until then, that one included
  int64_t keyframe_id = -1;   ///< the map's keyframe it was located in
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// Keyframes made before the placement, in a provisional frame, that it joined to the map.
  int keyframes_joined = 0;
};

class Slam {
 public:
  /// With `vocabulary` null, place recognition builds its vocabulary online. Throws
  /// std::invalid_argument naming an unusable option.
  explicit Slam(const SlamOptions& options = {}, std::shared_ptr<const Vocabulary> vocabulary = nullptr);
  /// Goes on from a saved map (map(), slam_map.h) in a new session: its world is the map's, its
  /// vocabulary the map's (fixed from then on; an empty one is rebuilt online from the
  /// keyframes). Frames are first relocalised (RelocalisationOptions): until one places the
  /// camera in the map (localized()), nothing is added. Throws InputError for a map that breaks
  /// its invariants, std::invalid_argument for an unusable option.
  Slam(std::shared_ptr<const SlamMap> map, const SlamOptions& options);

  /// What a later flight needs to go on from here (slam_map.h): a copy, without the provisional
  /// keyframes (not placed in the map's world: saved, they would be somewhere wrong).
  SlamMap map() const;
  /// False from the start on a saved map until a frame places the camera in it.
  bool localized() const { return localized_; }
  const std::optional<Relocalisation>& relocalisation() const { return relocalisation_; }
  /// The first provisional keyframe: this flight's, made before it was placed in the saved map,
  /// in a frame of their own (RelocalisationOptions::map_unplaced_after_s); -1 when there are none
  /// (never made, or joined to the map by the placement).
  int64_t provisional_from() const { return provisional_from_; }
  /// Is keyframe `id`'s optimised pose in the world (not provisional)?
  bool in_world(int64_t id) const { return provisional_from_ < 0 || id < provisional_from_; }
  /// This flight's session number (keyframes it makes carry it).
  int session() const { return session_; }
  /// The utime of session `s`'s first keyframe (0: it has none yet), and of the first frame this
  /// Slam was given since its start or reset (0: none): what published ids and revisions count
  /// from (slam_messages.h).
  int64_t session_start_utime(int s) const;
  int64_t first_frame_utime() const { return first_frame_utime_; }

  /// Would a frame at this odometry pose become a keyframe, be re-anchored or (not localized
  /// yet) be relocalised? (false for a frame whose pose is not finite; true after a restart of
  /// the odometry, bridged or not).
  bool wants_keyframe(const Eigen::Isometry3d& T_odom_camera, OdometryLink link = OdometryLink::kContinuous) const;

  /// Adds a frame seen at T_odom_camera; `link` says how that pose relates to the previous
  /// frame's (a bridged restart gives an odometry edge with the bridge's larger uncertainty, a
  /// broken one a weak edge of no motion). Throws InputError when the frame's utime does not
  /// increase or the pose is not a finite rigid transform. `odometry_covariance`, when given
  /// (continuous link only), is the odometry's own covariance of the motion from the
  /// reference (reference()) to this frame (right perturbation [rho; phi], OdometryChain::relative_covariance):
  /// the odometry edge then takes it (OdometryNoise::use_reported) instead of the constant model.
  /// `motion`: the camera's motion around the frame, for its features' timing correction
  /// (keyframe_motion(), place/frame_features.h); unknown = no correction. `sensor`: the
  /// camera's profile, whose noise its loops take (loop_verification(), place/loop_verifier.h).
  SlamStep add(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera,
               OdometryLink link = OdometryLink::kContinuous,
               const std::optional<Matrix6d>& odometry_covariance = std::nullopt,
               const sensors::FrameMotion& motion = {}, const sensors::SensorProfile& sensor = {});

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  /// Vertices are keyframes (poses T_world_camera); edges odometry and loop closures.
  const PoseGraph3d& graph() const { return graph_; }
  int64_t revision() const { return revision_; }
  int num_loop_closures() const { return loop_closures_; }
  /// Frames re-anchored on a covering keyframe instead of becoming keyframes.
  int num_reanchors() const { return reanchors_; }
  /// Why frames tried for re-anchoring became keyframes instead: no keyframe near their
  /// estimate, none verified (and the prediction too uncertain to carry), or located beyond the
  /// correction bound; and why others were carried at their predicted pose, neither located
  /// nor a keyframe.
  struct CoverageMisses {
    int none_near = 0, not_verified = 0, too_far = 0;
    int featureless = 0;         ///< covered, too few features to verify: carried
    int unverified_carried = 0;  ///< covered, none verified, prediction certain (localising only: any): carried
    int few_points_carried = 0;  ///< covered, none verified, prediction not certain, too few points for a keyframe: carried
    int closed_in_place = 0;     ///< covered, located beyond the bound: the loop closed between keyframes, no keyframe
  };
  const CoverageMisses& coverage_misses() const { return coverage_misses_; }
  /// Keyframes that let their features go to keep within the memory budget, and the bytes the
  /// others' features take.
  int num_thinned() const { return thinned_; }
  size_t feature_bytes() const { return feature_bytes_; }
  const OdometryReference& reference() const { return reference_; }
  /// False from a break of the odometry (a VO restart nothing bridged) until a loop closure to a
  /// keyframe from before the break places the new odometry in the map (until then world_pose()
  /// assumes no motion across the break, and is no measurement of where the camera is), and
  /// while not localized() in a saved map.
  bool odometry_placed() const { return gate_by_pose_ && localized_; }
  /// Verified loops refused because they disagreed with the odometry (loop_consistency.h).
  int num_inconsistent_loops() const { return inconsistent_loops_; }
  /// Marginal covariance of the reference keyframe's optimised T_world_camera after the last
  /// optimisation or re-anchoring (marginals.h: [rho; phi], right perturbation in the camera
  /// frame); nullopt before any, or when the graph did not determine it.
  const std::optional<Matrix6d>& reference_marginal() const { return reference_marginal_; }

  /// The optimised estimate of a camera seen at T_odom_camera after the reference: the
  /// reference's optimised pose composed with the odometry since.
  Eigen::Isometry3d world_pose(const Eigen::Isometry3d& T_odom_camera) const;

  /// Re-expresses the map in another world frame: every optimised pose T_world_camera becomes
  /// T_new_world * T_world_camera. A change of gauge only: edges, loop closures, covariances
  /// (right perturbations in the camera frame) and what later frames will do are unchanged;
  /// the revision grows by one. Throws std::invalid_argument for a non-rigid transform.
  void change_world(const Eigen::Isometry3d& T_new_world);

  /// Forgets this flight (as after construction: back to the saved map, if started from one).
  void reset();

 private:
  /// Per graph edge: the constant model's information of each odometry edge (identity for
  /// loop closures), for the loop-consistency gate (loop_consistency.h).
  std::vector<Matrix6d> gate_information_;
  void add_odometry_edge(const Keyframe& current, OdometryLink link, const std::optional<Matrix6d>& covariance);
  SlamStep close_loop(SlamStep step);
  /// Locates the frame in a covering keyframe and makes it the reference, or carries the
  /// reference to it when it is covered but too featureless to locate, or none verifies and its
  /// prediction is certain and local (carriable()); when one locates it beyond the correction
  /// bound, closes that loop without a keyframe if it can (close_loop_in_place()). False (and
  /// nothing changed) after an unplaced odometry break, when no keyframe covers it, one locates
  /// it beyond the bound and the loop cannot close in place, or none verifies it and it is not
  /// carriable.
  bool reanchor(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                const std::optional<Matrix6d>& odometry_covariance, const FrameFeatures& features,
                const sensors::SensorProfile& sensor, SlamStep& step);
  Eigen::Isometry3d reference_world_pose() const;
  /// A verified placement of the frame in keyframe `kf`: taken (the frame becomes the reference,
  /// located there) when enough placements of other frames agree with it, else kept as a
  /// hypothesis (RelocalisationOptions). True when taken.
  bool accept_placement(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, const Keyframe& kf,
                        const LoopConstraint& located);
  /// May a covered frame that none of its `covering` keyframes verified be carried at its
  /// prediction (`predicted`: in the reference's keyframe) rather than become a keyframe
  /// (CoverageOptions::carry_within_sigmas)?
  bool carriable(const std::vector<size_t>& covering, const Matrix6d& predicted) const;
  /// Makes the frame the reference at its predicted pose, in the reference's keyframe.
  void carry_reference(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                       const Matrix6d& predicted, SlamStep& step);
  /// Starts from the loaded map (reset()).
  void restore(const SlamMap& map);
  /// Not localized: places the frame in the map, or keeps it as a hypothesis (RelocalisationOptions);
  /// a placement joins the provisional keyframes to the map (join_provisional).
  SlamStep relocalise(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                      const std::optional<Matrix6d>& odometry_covariance, const FrameFeatures& features,
                      const sensors::SensorProfile& sensor);
  /// Not placed yet, for long enough: the frame may be a provisional keyframe (or re-anchored on one).
  SlamStep map_unplaced(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                        const std::optional<Matrix6d>& odometry_covariance, const sensors::FrameMotion& motion,
                        const sensors::SensorProfile& sensor, FrameFeatures features, SlamStep step);
  /// The placement of a frame in keyframe `kf` (`located`), whose odometry went on from the
  /// provisional reference `provisional`: moves the provisional keyframes rigidly into the map's
  /// world and joins them by one edge (kf to the reference's keyframe r), then optimises; the
  /// odometry goes on from r.
  void join_provisional(const OdometryReference& provisional, const RgbdFrame& frame,
                        const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                        const std::optional<Matrix6d>& odometry_covariance, const Keyframe& kf,
                        const LoopConstraint& located, SlamStep& step);
  /// Adds the loop edge kf -> to (measurement T_kf_to), optimises the graph.
  void add_loop_and_optimise(const Keyframe& kf, int64_t to, const Eigen::Isometry3d& T_kf_to,
                             const Matrix6d& information, SlamStep& step);
  /// Loops within a session join keyframes at least LoopSearchOptions::min_age_s apart: a younger
  /// one would re-measure what the odometry just measured.
  bool old_enough_for_a_loop(const Keyframe& k, int64_t utime) const;
  /// The loop gate (loop_consistency.h) on the constant odometry model of the graph's edges.
  bool passes_loop_gate(int64_t from, int64_t to, const Eigen::Isometry3d& T_from_to,
                        const OdometryBeyondChain* beyond = nullptr) const;
  /// A covered frame that keyframe `kf` located beyond the correction bound (`loop`: the
  /// re-anchoring's verification, the loop's without its spread test; `predicted`: the frame's
  /// covariance in the reference's keyframe r): when kf may close a loop (not r, old enough),
  /// the location passes the spread test and the edge passes the loop gate, closes the loop by
  /// an edge from kf to r through the frame, optimises, and makes the frame the reference
  /// (located in kf, or carried at its prediction when the optimised graph disagrees with the
  /// location). False, and nothing changed, otherwise.
  bool close_loop_in_place(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                           const Keyframe& kf, const Matrix6d& predicted, const LoopConstraint& loop,
                           SlamStep& step);
  /// Makes the frame a keyframe (features extracted), closes its loop if it has one.
  SlamStep add_keyframe(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                        const std::optional<Matrix6d>& odometry_covariance, const sensors::FrameMotion& motion,
                        const sensors::SensorProfile& sensor, FrameFeatures features, SlamStep step);
  /// The keyframe spacing rule: has the camera moved or turned enough since the reference?
  bool keyframe_due(const Eigen::Isometry3d& T_odom_camera, OdometryLink link) const;
  /// Puts the keyframes that keep their features in the bins of their optimised poses.
  void rebin();
  /// Thins keyframes (never `newest`) while their features exceed the budget.
  void keep_within_budget(std::optional<int64_t> newest);

  SlamOptions options_;
  std::shared_ptr<const SlamMap> loaded_;  ///< the saved map it started from, if any
  std::shared_ptr<const Vocabulary> vocabulary_;
  FeatureExtractor extractor_;
  std::unique_ptr<PlaceRecognizer> places_;
  std::vector<Keyframe> keyframes_;
  PoseGraph3d graph_;
  int64_t revision_ = 0;
  int loop_closures_ = 0;
  int inconsistent_loops_ = 0;
  int64_t last_utime_ = 0;
  bool have_frame_ = false;
  std::optional<Matrix6d> reference_marginal_;
  OdometryReference reference_;
  int reanchors_ = 0;
  CoverageMisses coverage_misses_;
  bool gate_by_pose_ = true;  ///< off from an odometry break until a loop closure places it
  int64_t unplaced_from_ = -1;  ///< gate off: the first keyframe after the break (loops to older ones place it)
  ViewBins matchable_;        ///< keyframes that still have their features, by view
  size_t feature_bytes_ = 0;  ///< of those keyframes
  int thinned_ = 0;
  int session_ = 0;
  std::vector<int64_t> session_start_utime_;  ///< per session, its first keyframe's utime
  int64_t first_frame_utime_ = 0;
  bool localized_ = true;
  int64_t lost_since_utime_ = -1;  ///< localisation only: located too far at this frame (-1: not lost)
  std::optional<Relocalisation> relocalisation_;
  int relocalisation_tries_ = 0;
  struct Placement {  ///< a verified relocalisation hypothesis
    int64_t utime;
    Eigen::Isometry3d T_world_odom;
  };
  std::vector<Placement> placements_;  ///< hypotheses within max_span_s, oldest first
  int64_t provisional_from_ = -1;     ///< the first provisional keyframe (-1: none)
  bool break_pending_ = false;        ///< the odometry broke since the last keyframe or placement
};

}  // namespace kestrel::slam
