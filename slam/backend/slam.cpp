#include "slam/backend/slam.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "slam/posegraph/marginals.h"

namespace kestrel::slam {
namespace {

void check_options(const SlamOptions& o) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("slam: ") + what);
  };
  require(o.keyframes.min_translation_m >= 0.0 && o.keyframes.min_rotation_rad >= 0.0,
          "keyframe thresholds must be >= 0");
  const CoverageOptions& c = o.coverage;
  require(c.max_translation_m >= 0.0 && c.max_rotation_rad >= 0.0 && c.max_correction_m >= 0.0 &&
              c.max_correction_rad >= 0.0 && c.carry_within_sigmas >= 0.0 &&
              c.max_candidates >= 1 && c.min_points_to_verify >= 0,
          "coverage distances, carry_within_sigmas and min_points_to_verify must be >= 0 and max_candidates >= 1");
  const KeyframeMemoryOptions& m = o.memory;
  require(std::isfinite(m.max_megabytes) && m.max_megabytes > 0.0, "memory.max_megabytes must be > 0");
  require(std::isfinite(m.bin_size_m) && m.bin_size_m > 0.0, "memory.bin_size_m must be > 0");
  require(m.bin_angle_deg > 0.0 && m.bin_angle_deg <= 180.0, "memory.bin_angle_deg must be in (0, 180]");
  require(o.loops.min_age_s >= 0.0, "loops.min_age_s must be >= 0");
  require(o.loops.max_candidates >= 1, "loops.max_candidates must be >= 1");
  require(!o.localize_only || c.reuse_keyframes, "localize_only needs coverage.reuse_keyframes");
  const RelocalisationOptions& r = o.relocalisation;
  require(r.max_candidates >= 1 && r.confirmations >= 1, "relocalisation: max_candidates and confirmations must be >= 1");
  require(r.max_disagreement_m >= 0.0 && r.max_disagreement_rad >= 0.0 && r.max_span_s >= 0.0,
          "relocalisation bounds must be >= 0");
  require(r.map_unplaced_after_s >= 0.0, "relocalisation.map_unplaced_after_s must be >= 0 (infinite: never)");
  const OdometryNoise& n = o.odometry;
  require(n.translation_floor_m > 0.0 && n.rotation_floor_rad > 0.0, "odometry noise floors must be > 0");
  require(n.translation_per_m >= 0.0 && n.rotation_per_rad >= 0.0 && n.rotation_per_m >= 0.0,
          "odometry noise rates must be >= 0");
  require(n.break_translation_m > 0.0 && n.break_rotation_rad > 0.0, "odometry break noise must be > 0");
  require(n.bridge_translation_m > 0.0 && n.bridge_rotation_rad > 0.0, "odometry bridge noise must be > 0");
  require(n.reported_translation_floor_m > 0.0 && n.reported_rotation_floor_rad > 0.0,
          "odometry reported-covariance floors must be > 0");
}

const SlamOptions& checked(const SlamOptions& o) {
  check_options(o);
  return o;
}

// Information of an odometry edge in the pose graph's error convention (spaces.h): the
// rotational part of the error is vec(q) ~ phi / 2, hence the factor 4.
Matrix6d odometry_information(const Eigen::Isometry3d& T_prev_cur, const OdometryNoise& n, OdometryLink link) {
  double sigma_t, sigma_r;
  if (link == OdometryLink::kBroken) {
    sigma_t = n.break_translation_m;
    sigma_r = n.break_rotation_rad;
  } else {
    const double distance = T_prev_cur.translation().norm();
    const double angle = so3::angle(T_prev_cur.linear());
    const bool bridged = link == OdometryLink::kBridged;
    sigma_t = (bridged ? n.bridge_translation_m : n.translation_floor_m) + n.translation_per_m * distance;
    sigma_r = (bridged ? n.bridge_rotation_rad : n.rotation_floor_rad) + n.rotation_per_rad * angle +
              n.rotation_per_m * distance;
  }
  Matrix6d info = Matrix6d::Zero();
  info.diagonal().head<3>().setConstant(1.0 / (sigma_t * sigma_t));
  info.diagonal().tail<3>().setConstant(4.0 / (sigma_r * sigma_r));
  return info;
}

// The pose graph's error of a right perturbation [rho; phi] of a measurement is [rho; phi / 2]
// (spaces.h): covariance <-> information of an edge.
Matrix6d error_scale() {
  Matrix6d S = Matrix6d::Identity();
  S.bottomRightCorner<3, 3>() *= 0.5;
  return S;
}
Matrix6d right_covariance(const Matrix6d& information) {
  const Matrix6d S_inv = error_scale().inverse();
  const Matrix6d cov = S_inv * information.inverse() * S_inv;
  return 0.5 * (cov + cov.transpose());
}
Matrix6d information_of(const Matrix6d& right_covariance) {
  const Matrix6d S = error_scale();
  const Matrix6d info = (S * right_covariance * S).inverse();
  return 0.5 * (info + info.transpose());
}

// An odometry edge's information from the odometry's own covariance of a right perturbation [rho; phi] of T_prev_cur
// (the measurement Z of the edge): the error of Z * Exp(xi) is [rho; phi / 2] to first order.
Matrix6d reported_odometry_information(const Matrix6d& covariance, const OdometryNoise& n) {
  Matrix6d cov = covariance;
  cov.diagonal().head<3>().array() += n.reported_translation_floor_m * n.reported_translation_floor_m;
  cov.diagonal().tail<3>().array() += n.reported_rotation_floor_rad * n.reported_rotation_floor_rad;
  return information_of(cov);
}

// The information of Z = A * B from A's (right-perturbation covariance) and B's (an edge's
// information): A Exp(a) B Exp(b) = A B Exp(Ad(B^-1) a) Exp(b).
Matrix6d composed_information(const Eigen::Isometry3d& B, const Matrix6d& covariance_A, const Matrix6d& information_B) {
  if (covariance_A.isZero(0.0)) return information_B;
  const Matrix6d Ad = se3::adjoint(B.inverse());
  return information_of(Ad * covariance_A * Ad.transpose() + right_covariance(information_B));
}

// The 99 % quantile of the chi-square distribution with 6 degrees of freedom: two estimates of a
// pose agree when their difference's Mahalanobis norm squared is below it.
constexpr double kChi2Of6Dof99Percent = 16.812;

// A loop edge kf -> r through one frame, located in keyframe kf (`located`: T_kf_frame and its
// information) and predicted in keyframe r (T_r_frame, with its right-perturbation covariance):
// T_kf_r = T_kf_frame T_r_frame^-1, the two uncertainties composed.
struct EdgeThroughFrame {
  Eigen::Isometry3d T_kf_r;
  Matrix6d information;
};
EdgeThroughFrame edge_through_frame(const LoopConstraint& located, const Eigen::Isometry3d& T_r_frame,
                                    const Matrix6d& covariance_r_frame) {
  // Inverted: T Exp(d) inverse = T^-1 Exp(-Ad(T) d).
  const Eigen::Isometry3d T_frame_r = T_r_frame.inverse();
  const Matrix6d Ad = se3::adjoint(T_r_frame);
  const Matrix6d information_frame_r = information_of(Ad * covariance_r_frame * Ad.transpose());
  return {located.T_candidate_query * T_frame_r,
          composed_information(T_frame_r, right_covariance(located.information), information_frame_r)};
}

// The standard deviation along the most uncertain axis of a 3x3 covariance (NaN when it is not finite).
double largest_sigma(const Eigen::Matrix3d& covariance) {
  if (!covariance.allFinite()) return std::nan("");
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues().maxCoeff()));
}

}  // namespace

Matrix6d odometry_edge_information(const Eigen::Isometry3d& T_prev_cur, const OdometryNoise& noise, OdometryLink link,
                                   const std::optional<Matrix6d>& reported_covariance) {
  if (link == OdometryLink::kContinuous && reported_covariance && noise.use_reported &&
      reported_covariance->allFinite()) {
    const Matrix6d reported = reported_odometry_information(*reported_covariance, noise);
    if (reported.allFinite() && Eigen::SelfAdjointEigenSolver<Matrix6d>(reported).eigenvalues().minCoeff() > 0.0) {
      return reported;
    }
  }
  return odometry_information(T_prev_cur, noise, link);
}

size_t memory_of(const FrameFeatures& f) {
  return f.keypoints.capacity() * sizeof(cv::KeyPoint) + f.descriptors.total() * f.descriptors.elemSize() +
         f.points.capacity() * sizeof(Eigen::Vector3d);
}

Slam::Slam(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary)
    : options_(checked(options)),
      vocabulary_(std::move(vocabulary)),
      extractor_(options.features),
      matchable_(options.memory.bin_size_m, options.memory.bin_angle_deg) {
  reset();
}

Slam::Slam(std::shared_ptr<const SlamMap> map, const SlamOptions& options)
    : options_(checked(options)),
      extractor_(options.features),
      matchable_(options.memory.bin_size_m, options.memory.bin_angle_deg) {
  if (!map) throw std::invalid_argument("slam: no map to start from");
  check_map(*map, "slam map");
  loaded_ = std::move(map);
  // The map's vocabulary indexed its keyframes; an empty one (an online vocabulary never
  // trained) is rebuilt online as the keyframes are added again.
  if (loaded_->vocabulary && !loaded_->vocabulary->empty()) vocabulary_ = loaded_->vocabulary;
  reset();
}

int64_t Slam::session_start_utime(int s) const {
  return s >= 0 && static_cast<size_t>(s) < session_start_utime_.size() ? session_start_utime_[static_cast<size_t>(s)] : 0;
}

SlamMap Slam::map() const {
  SlamMap map;
  map.keyframes = keyframes_;
  map.graph = graph_;
  map.gate_information = gate_information_;
  map.gate_information.resize(graph_.edges.size(), Matrix6d::Identity());
  if (provisional_from_ >= 0) {
    // The provisional keyframes are the newest and only their own edges touch them.
    const auto kept = static_cast<size_t>(provisional_from_);
    map.keyframes.resize(kept);
    PoseGraph3d graph;
    for (size_t v = 0; v < kept; ++v) graph.add_vertex(graph_.ids[v], graph_.poses[v], graph_.fixed[v] != 0);
    std::vector<Matrix6d> gate;
    for (size_t e = 0; e < graph_.edges.size(); ++e) {
      const auto& edge = graph_.edges[e];
      if (static_cast<size_t>(edge.from) >= kept || static_cast<size_t>(edge.to) >= kept) continue;
      graph.edges.push_back(edge);
      gate.push_back(map.gate_information[e]);
    }
    map.graph = std::move(graph);
    map.gate_information = std::move(gate);
  }
  map.vocabulary = places_->vocabulary_in_use();
  const bool added = std::any_of(map.keyframes.begin(), map.keyframes.end(),
                                 [this](const Keyframe& k) { return k.session == session_; });
  map.sessions = session_ + (added ? 1 : 0);
  map.revision = revision_;
  return map;
}

void Slam::restore(const SlamMap& map) {
  keyframes_ = map.keyframes;
  for (const Keyframe& kf : keyframes_) {
    if (static_cast<size_t>(kf.session) >= session_start_utime_.size())
      session_start_utime_.resize(static_cast<size_t>(kf.session) + 1, 0);
    if (session_start_utime_[static_cast<size_t>(kf.session)] == 0) session_start_utime_[static_cast<size_t>(kf.session)] = kf.utime;
  }
  graph_ = map.graph;
  gate_information_ = map.gate_information;
  for (const Keyframe& kf : keyframes_) {
    places_->add(kf.thinned ? cv::Mat() : kf.features.descriptors);
    if (kf.thinned) {
      places_->forget(static_cast<int>(kf.id));
      ++thinned_;
    } else {
      feature_bytes_ += memory_of(kf.features);
    }
  }
  rebin();
  keep_within_budget(std::nullopt);
  session_ = map.sessions;
  revision_ = map.revision + 1;  // the loaded graph is a change after the one saved
  // An empty map has nowhere to be placed in: the flight maps from nothing.
  localized_ = keyframes_.empty();
}

void Slam::reset() {
  places_ = std::make_unique<PlaceRecognizer>(options_.place, vocabulary_);
  keyframes_.clear();
  graph_ = PoseGraph3d{};
  gate_information_.clear();
  revision_ = 0;
  loop_closures_ = 0;
  inconsistent_loops_ = 0;
  last_utime_ = 0;
  have_frame_ = false;
  gate_by_pose_ = true;
  unplaced_from_ = -1;
  reference_marginal_.reset();
  reference_ = OdometryReference{};
  reanchors_ = 0;
  coverage_misses_ = CoverageMisses{};
  matchable_.clear();
  feature_bytes_ = 0;
  thinned_ = 0;
  session_ = 0;
  session_start_utime_.clear();
  first_frame_utime_ = 0;
  localized_ = true;
  lost_since_utime_ = -1;
  relocalisation_.reset();
  relocalisation_tries_ = 0;
  placements_.clear();
  provisional_from_ = -1;
  break_pending_ = false;
  if (loaded_) restore(*loaded_);
}

void Slam::rebin() {
  // The thinning bins follow the optimised poses, as the mapper's follow SLAM's graph: after a
  // loop corrects drift, views of one place share a bin again.
  // Provisional keyframes are binned once joined: their poses are in a frame of their own,
  // where they would share bins with the map's keyframes and have those thinned.
  for (const Keyframe& kf : keyframes_)
    if (!kf.thinned && in_world(kf.id)) matchable_.insert(kf.id, graph_.poses[static_cast<size_t>(kf.id)]);
}

void Slam::keep_within_budget(std::optional<int64_t> newest) {
  const double budget = options_.memory.max_megabytes * 1e6;
  while (static_cast<double>(feature_bytes_) > budget) {
    const std::optional<int64_t> victim = matchable_.first_to_thin(newest);
    if (!victim) return;
    Keyframe& kf = keyframes_[static_cast<size_t>(*victim)];
    feature_bytes_ -= memory_of(kf.features);
    kf.features = FrameFeatures{};
    kf.thinned = true;
    places_->forget(static_cast<int>(kf.id));
    matchable_.erase(kf.id);
    ++thinned_;
  }
}

void Slam::change_world(const Eigen::Isometry3d& T_new_world) {
  if (!se3::is_valid(T_new_world, 1e-6)) throw std::invalid_argument("slam: change_world needs a rigid transform");
  for (auto& T : graph_.poses) T = T_new_world * T;
  rebin();
  ++revision_;
}

bool Slam::wants_keyframe(const Eigen::Isometry3d& T_odom_camera, OdometryLink link) const {
  if (!T_odom_camera.matrix().allFinite()) return false;
  if (!localized_) return true;
  return keyframe_due(T_odom_camera, link);
}

bool Slam::keyframe_due(const Eigen::Isometry3d& T_odom_camera, OdometryLink link) const {
  // After a restart the earlier keyframe's odometry ends: the edge must span only the gap.
  if (keyframes_.empty() || link != OdometryLink::kContinuous) return true;
  const Eigen::Isometry3d T_last_cur = reference_.T_odom_camera.inverse() * T_odom_camera;
  return T_last_cur.translation().norm() >= options_.keyframes.min_translation_m ||
         so3::angle(T_last_cur.linear()) >= options_.keyframes.min_rotation_rad;
}

Eigen::Isometry3d Slam::reference_world_pose() const {
  return graph_.poses[static_cast<size_t>(reference_.keyframe_id)] * reference_.T_keyframe_camera;
}

Eigen::Isometry3d Slam::world_pose(const Eigen::Isometry3d& T_odom_camera) const {
  if (keyframes_.empty()) return T_odom_camera;
  return reference_world_pose() * reference_.T_odom_camera.inverse() * T_odom_camera;
}

namespace {
OdometryLink weaker(OdometryLink a, OdometryLink b) { return static_cast<int>(a) >= static_cast<int>(b) ? a : b; }
}  // namespace

void Slam::add_odometry_edge(const Keyframe& current, OdometryLink link, const std::optional<Matrix6d>& covariance) {
  // After a break the odometry poses of the two are unrelated: assume no motion, weakly.
  const Eigen::Isometry3d T_ref_cur = link == OdometryLink::kBroken
                                          ? Eigen::Isometry3d::Identity()
                                          : reference_.T_odom_camera.inverse() * current.T_odom_camera;
  // From the reference's keyframe: through the frame located in it, when re-anchored.
  const Eigen::Isometry3d T_prev_cur = reference_.T_keyframe_camera * T_ref_cur;
  const Matrix6d information = composed_information(
      T_ref_cur, reference_.covariance, odometry_edge_information(T_ref_cur, options_.odometry, link, covariance));
  graph_.add_edge(static_cast<int>(reference_.keyframe_id), static_cast<int>(current.id), T_prev_cur, information,
                  EdgeKind::kOdometry);
  // The loop gate's model of the whole edge: as weak as the weakest link since the keyframe
  // (the reference's covariance already carries a bridge crossed before it, the information
  // above does not need it twice).
  gate_information_.resize(graph_.edges.size() - 1, Matrix6d::Identity());
  gate_information_.push_back(odometry_information(T_prev_cur, options_.odometry, current.link));
}

SlamStep Slam::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                   const std::optional<Matrix6d>& odometry_covariance, const sensors::FrameMotion& motion,
                   const sensors::SensorProfile& sensor) {
  const bool odometry_broken = link == OdometryLink::kBroken;
  if (have_frame_ && frame.utime <= last_utime_) {
    throw InputError("slam: frame utime " + std::to_string(frame.utime) + " does not follow " +
                     std::to_string(last_utime_));
  }
  if (!se3::is_valid(T_odom_camera, 1e-6)) {
    throw InputError("slam: odometry pose of frame " + std::to_string(frame.utime) + " is not a rigid transform");
  }
  if (!have_frame_) first_frame_utime_ = frame.utime;
  have_frame_ = true;
  last_utime_ = frame.utime;
  if (odometry_broken) {
    // The keyframe this frame makes is the first of odometry that nothing places in the map.
    if (gate_by_pose_) unplaced_from_ = static_cast<int64_t>(keyframes_.size());
    gate_by_pose_ = false;
  }
  // Placement hypotheses place the odometry frame: across a break that frame changes.
  if (odometry_broken) placements_.clear();
  if (odometry_broken) break_pending_ = true;
  if (!localized_ && lost_since_utime_ >= 0 &&
      frame.utime - lost_since_utime_ > static_cast<int64_t>(std::llround(options_.relocalisation.max_span_s * 1e6))) {
    // Localisation only, not confirmed elsewhere in time: the estimate carries on from where it was.
    localized_ = true;
    lost_since_utime_ = -1;
  }
  // The odometry broke at a frame that made no keyframe (lost, localising only) and nothing has
  // placed it since: this frame's odometry is still unrelated to the reference's.
  if (localized_ && break_pending_) link = OdometryLink::kBroken;
  if (!localized_) {
    FrameFeatures features = extractor_.extract(frame, motion);
    SlamStep step = relocalise(frame, T_odom_camera, link, odometry_covariance, features, sensor);  // a break cleared the placements (above)
    // Lost while localising only (not a camera that was never placed): the wait is short, and
    // the map is not to grow.
    if (step.relocalised || lost_since_utime_ >= 0) return step;
    const double unplaced_s = 1e-6 * static_cast<double>(frame.utime - first_frame_utime_);
    if (!(unplaced_s >= options_.relocalisation.map_unplaced_after_s)) return step;
    return map_unplaced(frame, T_odom_camera, link, odometry_covariance, motion, sensor, std::move(features), step);
  }
  SlamStep step;
  if (!wants_keyframe(T_odom_camera, link)) return step;

  FrameFeatures features = extractor_.extract(frame, motion);
  // A VO restart the estimator bridged keeps a usable estimate: covered ground re-anchors it
  // too (a flight with many restarts would otherwise make a keyframe at each). A broken one
  // does not know where it is: a keyframe, and loop closure, place it.
  if (link != OdometryLink::kBroken && !keyframes_.empty() && options_.coverage.reuse_keyframes &&
      reanchor(frame, T_odom_camera, link, odometry_covariance, features, sensor, step)) {
    return step;
  }
  return add_keyframe(frame, T_odom_camera, link, odometry_covariance, motion, sensor, std::move(features), step);
}

SlamStep Slam::map_unplaced(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                            const std::optional<Matrix6d>& odometry_covariance, const sensors::FrameMotion& motion,
                            const sensors::SensorProfile& sensor, FrameFeatures features, SlamStep step) {
  const bool first = provisional_from_ < 0;
  if (!first && !keyframe_due(T_odom_camera, link)) return step;
  // Covered ground re-anchors on the provisional keyframes as it does on the map's
  // (reanchor() looks at no other keyframe meanwhile).
  if (!first && link != OdometryLink::kBroken && options_.coverage.reuse_keyframes &&
      reanchor(frame, T_odom_camera, link, odometry_covariance, features, sensor, step)) {
    return step;
  }
  if (first) {
    // A frame of its own from here: a break before it is no break within it.
    provisional_from_ = static_cast<int64_t>(keyframes_.size());
    gate_by_pose_ = true;
    unplaced_from_ = -1;
  }
  return add_keyframe(frame, T_odom_camera, link, odometry_covariance, motion, sensor, std::move(features), step);
}

SlamStep Slam::add_keyframe(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                            const std::optional<Matrix6d>& odometry_covariance, const sensors::FrameMotion& motion,
                            const sensors::SensorProfile& sensor, FrameFeatures features, SlamStep step) {
  const bool odometry_broken = link == OdometryLink::kBroken;
  // The first keyframe of the flight, or the first provisional one: the first of its frame,
  // where the odometry puts it, with no edge (the first provisional one is not the gauge: the
  // optimiser holds a component that reaches no fixed vertex at its first vertex).
  const bool first_of_frame = keyframes_.empty() || provisional_from_ == static_cast<int64_t>(keyframes_.size());
  Keyframe kf;
  kf.id = static_cast<int64_t>(keyframes_.size());
  kf.utime = frame.utime;
  kf.session = session_;
  if (session_start_utime_.size() <= static_cast<size_t>(session_)) session_start_utime_.resize(static_cast<size_t>(session_) + 1, 0);
  if (session_start_utime_[static_cast<size_t>(session_)] == 0) session_start_utime_[static_cast<size_t>(session_)] = frame.utime;
  kf.T_odom_camera = T_odom_camera;
  kf.T_body_camera = frame.T_body_camera;
  kf.T_camera_depth = motion.T_rgb_depth();
  kf.link = first_of_frame ? OdometryLink::kContinuous : weaker(link, reference_.link);
  kf.sensor = sensor;
  kf.features = std::move(features);
  const Eigen::Isometry3d T_world_camera =
      first_of_frame ? T_odom_camera : (odometry_broken ? reference_world_pose() : world_pose(T_odom_camera));
  graph_.add_vertex(kf.id, T_world_camera, keyframes_.empty());
  if (!first_of_frame) add_odometry_edge(kf, link, odometry_covariance);
  break_pending_ = false;  // the break is this keyframe's edge (or before its frame's start)
  reference_ = OdometryReference{kf.id, kf.utime, kf.T_odom_camera, kf.T_body_camera};
  reference_marginal_.reset();  // the previous reference's: a loop closure below gives this one's
  keyframes_.push_back(std::move(kf));
  step.keyframe = true;
  step.keyframe_id = keyframes_.back().id;
  step = close_loop(std::move(step));
  const Keyframe& added = keyframes_.back();
  places_->add(added.features.descriptors);
  if (in_world(added.id)) matchable_.insert(added.id, graph_.poses.back());
  feature_bytes_ += memory_of(added.features);
  keep_within_budget(added.id);
  return step;
}

SlamStep Slam::close_loop(SlamStep step) {
  const Keyframe& query = keyframes_.back();
  const Eigen::Isometry3d& T_world_query = graph_.poses.back();
  const LoopSearchOptions& lo = options_.loops;
  const bool gate = gate_by_pose_ && lo.max_distance_m > 0.0;
  auto allowed = [&](int entry) {
    const Keyframe& k = keyframes_[static_cast<size_t>(entry)];
    // Time orders keyframes within a flight only (slam_map.h). The minimum age keeps a loop
    // from re-measuring what the odometry just measured; across a break no loop has placed
    // yet, the keyframes from before it are no odometry neighbours, however recent (a VO lost
    // over a hover gets its place back at once, not 4 s later).
    // Not placed in the saved map yet: the map's keyframes are for relocalise() (which confirms
    // a placement before it joins the two); only the provisional ones are loop candidates.
    if (!in_world(query.id) && in_world(k.id)) return false;
    const bool across_unplaced_break = !gate_by_pose_ && unplaced_from_ >= 0 && k.id < unplaced_from_;
    if (!across_unplaced_break && !old_enough_for_a_loop(k, query.utime)) return false;
    if (!gate) return true;
    const Eigen::Isometry3d& T_world_k = graph_.poses[static_cast<size_t>(entry)];
    return se3::translation_distance(T_world_k, T_world_query) <= lo.max_distance_m &&
           se3::rotation_distance(T_world_k, T_world_query) <= lo.max_angle_rad;
  };
  const std::vector<BowMatch> candidates =
      places_->query(query.features.descriptors, lo.max_candidates, allowed);
  for (const BowMatch& candidate : candidates) {
    if (candidate.score < lo.min_score) break;
    ++step.candidates;
    const Keyframe& earlier = keyframes_[static_cast<size_t>(candidate.entry)];
    // The seed depends on the pair only, so that a replay verifies identically.
    const uint64_t seed = static_cast<uint64_t>(earlier.id) * 1000003u + static_cast<uint64_t>(query.id);
    step.loop = verify_loop(query.features, earlier.features,
                            loop_verification(options_.verification, earlier.sensor, query.sensor), seed);
    if (!step.loop.accepted) continue;
    if (gate && !passes_loop_gate(earlier.id, query.id, step.loop.T_candidate_query)) {
      step.loop.accepted = false;
      ++step.inconsistent;
      ++inconsistent_loops_;
      continue;
    }
    graph_.add_edge(static_cast<int>(earlier.id), static_cast<int>(query.id), step.loop.T_candidate_query,
                    step.loop.information, EdgeKind::kLoopClosure);
    step.loop_closed = true;
    step.loop_keyframe_id = earlier.id;
    ++loop_closures_;
    step.optimisation = optimize(graph_, options_.optimizer);
    rebin();
    reference_marginal_ = marginal_covariance(graph_, static_cast<int>(query.id), options_.optimizer.kernel);
    ++revision_;
    // Only a loop to a keyframe from before the break places the odometry since it in the map.
    if (!gate_by_pose_ && earlier.id < unplaced_from_) {
      gate_by_pose_ = true;
      unplaced_from_ = -1;
    }
    break;  // the paper stops at the first success
  }
  return step;
}

bool Slam::accept_placement(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, const Keyframe& kf,
                            const LoopConstraint& located) {
  const RelocalisationOptions& r = options_.relocalisation;
  const auto span_us = static_cast<int64_t>(std::llround(r.max_span_s * 1e6));
  placements_.erase(std::remove_if(placements_.begin(), placements_.end(),
                                   [&](const Placement& p) { return p.utime < frame.utime - span_us; }),
                    placements_.end());
  const size_t k = static_cast<size_t>(kf.id);
  const Eigen::Isometry3d T_world_odom = graph_.poses[k] * located.T_candidate_query * T_odom_camera.inverse();
  int agreeing = 1;  // this one
  for (const Placement& p : placements_) {
    const Eigen::Isometry3d D = p.T_world_odom.inverse() * T_world_odom;
    if (D.translation().norm() <= r.max_disagreement_m && so3::angle(D.linear()) <= r.max_disagreement_rad) ++agreeing;
  }
  if (agreeing < r.confirmations) {
    placements_.push_back({frame.utime, T_world_odom});
    return false;
  }
  // Placed: the odometry goes on from this frame, located in keyframe k, as after a
  // re-anchoring; the next keyframe's edge joins the map there.
  placements_.clear();
  reference_ = OdometryReference{kf.id,          frame.utime, T_odom_camera, frame.T_body_camera,
                                 located.T_candidate_query, right_covariance(located.information)};
  reference_marginal_ = marginal_covariance(graph_, static_cast<int>(k), options_.optimizer.kernel);
  return true;
}

SlamStep Slam::relocalise(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                          const std::optional<Matrix6d>& odometry_covariance, const FrameFeatures& features,
                          const sensors::SensorProfile& sensor) {
  const RelocalisationOptions& r = options_.relocalisation;
  SlamStep step;
  ++relocalisation_tries_;
  if (static_cast<int>(features.num_points()) < options_.verification.min_inliers) return step;
  // Across a break nothing relates this frame to the provisional keyframes: placed now, the join
  // would fix them where an assumed stillness puts them. It becomes a provisional keyframe (on a
  // break edge, as in any flight) and the next frames are placed from it.
  if (link == OdometryLink::kBroken && provisional_from_ >= 0) return step;
  const std::vector<BowMatch> candidates = places_->query(features.descriptors, r.max_candidates, [this](int entry) {
    return !keyframes_[static_cast<size_t>(entry)].thinned && in_world(entry);
  });
  for (const BowMatch& candidate : candidates) {
    ++step.candidates;
    const Keyframe& kf = keyframes_[static_cast<size_t>(candidate.entry)];
    const uint64_t seed = static_cast<uint64_t>(kf.id) * 1000003u + static_cast<uint64_t>(frame.utime);
    VerificationOptions verification = loop_verification(options_.verification, kf.sensor, sensor);
    verification.ratio = r.match_ratio;
    const LoopConstraint located = verify_loop(features, kf.features, verification, seed);
    step.loop = located;
    if (!located.accepted) continue;
    const OdometryReference provisional = reference_;  // accept_placement() replaces it
    if (!accept_placement(frame, T_odom_camera, kf, located)) return step;  // one placement per frame: the best verified
    int joined = 0;
    if (provisional_from_ >= 0) {
      joined = static_cast<int>(keyframes_.size()) - static_cast<int>(provisional_from_);
      join_provisional(provisional, frame, T_odom_camera, link, odometry_covariance, kf, located, step);
    }
    localized_ = true;
    lost_since_utime_ = -1;
    gate_by_pose_ = true;
    unplaced_from_ = -1;
    break_pending_ = false;  // placed: the odometry since is in the map
    relocalisation_ = Relocalisation{frame.utime, relocalisation_tries_, kf.id, reference_world_pose(), joined};
    relocalisation_tries_ = 0;
    step.relocalised = true;
    step.reanchor_keyframe_id = kf.id;
    return step;
  }
  return step;
}

void Slam::join_provisional(const OdometryReference& provisional, const RgbdFrame& frame,
                            const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                            const std::optional<Matrix6d>& odometry_covariance, const Keyframe& kf,
                            const LoopConstraint& located, SlamStep& step) {
  // The placed frame in the provisional reference's keyframe r, through the odometry since the
  // reference (and the reference's own uncertainty in r, when it was re-anchored or carried),
  // as an odometry edge from r to it would be (never across a break: relocalise()).
  const Eigen::Isometry3d T_ref_frame = provisional.T_odom_camera.inverse() * T_odom_camera;
  const Eigen::Isometry3d T_r_frame = provisional.T_keyframe_camera * T_ref_frame;
  const Matrix6d covariance_r_frame = right_covariance(composed_information(
      T_ref_frame, provisional.covariance,
      odometry_edge_information(T_ref_frame, options_.odometry, link,
                                link == OdometryLink::kContinuous ? odometry_covariance : std::nullopt)));
  // The join: r in the map's keyframe, as the placement and the odometry put it.
  const EdgeThroughFrame join = edge_through_frame(located, T_r_frame, covariance_r_frame);
  // The provisional keyframes move rigidly so that r sits where the join puts it: they keep
  // their shape, and the optimiser starts from a graph the join already agrees with.
  const auto r = static_cast<size_t>(provisional.keyframe_id);
  const auto k = static_cast<size_t>(kf.id);
  const Eigen::Isometry3d T_world_provisional = graph_.poses[k] * join.T_kf_r * graph_.poses[r].inverse();
  for (size_t v = static_cast<size_t>(provisional_from_); v < graph_.poses.size(); ++v)
    graph_.poses[v] = T_world_provisional * graph_.poses[v];
  provisional_from_ = -1;
  // The odometry goes on from r (not from kf, as accept_placement put it: the next keyframe's
  // edge would use the placement a second time).
  add_loop_and_optimise(kf, static_cast<int64_t>(r), join.T_kf_r, join.information, step);
  reference_ = OdometryReference{provisional.keyframe_id, frame.utime,        T_odom_camera,   frame.T_body_camera,
                                 T_r_frame,                covariance_r_frame, weaker(link, provisional.link)};
  reference_marginal_ = marginal_covariance(graph_, static_cast<int>(r), options_.optimizer.kernel);
}

void Slam::add_loop_and_optimise(const Keyframe& kf, int64_t to, const Eigen::Isometry3d& T_kf_to,
                                 const Matrix6d& information, SlamStep& step) {
  graph_.add_edge(static_cast<int>(kf.id), static_cast<int>(to), T_kf_to, information, EdgeKind::kLoopClosure);
  step.loop_closed = true;
  step.loop_keyframe_id = kf.id;
  ++loop_closures_;
  step.optimisation = optimize(graph_, options_.optimizer);
  rebin();
  ++revision_;
}

bool Slam::old_enough_for_a_loop(const Keyframe& k, int64_t utime) const {
  const auto min_age_us = static_cast<int64_t>(std::llround(options_.loops.min_age_s * 1e6));
  return k.session != session_ || k.utime <= utime - min_age_us;
}

bool Slam::passes_loop_gate(int64_t from, int64_t to, const Eigen::Isometry3d& T_from_to,
                            const OdometryBeyondChain* beyond) const {
  return check_loop_against_odometry(graph_, static_cast<int>(from), static_cast<int>(to), T_from_to,
                                     options_.loop_consistency, &gate_information_, beyond)
      .consistent;
}

bool Slam::close_loop_in_place(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                               const Keyframe& kf, const Matrix6d& predicted, const LoopConstraint& loop,
                               SlamStep& step) {
  const int64_t r = reference_.keyframe_id;
  if (!options_.coverage.close_loops_in_place || kf.id == r) return false;
  // A loop candidate as close_loop() takes them: old enough not to re-measure what the odometry
  // just measured, and verified as a loop is. The re-anchoring's verification is the loop's
  // without the spread test, on the same seed: its location stands once the spread passes.
  if (!old_enough_for_a_loop(kf, frame.utime)) return false;
  ++step.candidates;
  if (loop.spread_m < options_.verification.min_spread_m) return false;
  const Eigen::Isometry3d T_r_frame =
      reference_.T_keyframe_camera * reference_.T_odom_camera.inverse() * T_odom_camera;
  const EdgeThroughFrame edge = edge_through_frame(loop, T_r_frame, predicted);
  // The gate allows for the odometry edges between the two keyframes and for the odometry from
  // r to the frame, in the constant model, as the edge of a keyframe made at the frame would
  // have it. Refused, nothing is counted: that keyframe is made, and its own loop search and
  // gate judge the same loop.
  const OdometryBeyondChain to_frame{T_r_frame,
                                     odometry_information(T_r_frame, options_.odometry, weaker(link, reference_.link))};
  if (options_.loops.max_distance_m > 0.0 && !passes_loop_gate(kf.id, r, edge.T_kf_r, &to_frame)) return false;
  add_loop_and_optimise(kf, r, edge.T_kf_r, edge.information, step);
  step.loop = loop;
  ++coverage_misses_.closed_in_place;
  // The frame, against the optimised graph: the loop moved the keyframes as far as its edge
  // could, which is little when the odometry to the frame was uncertain. Where the graph and the
  // location agree within their uncertainties the frame is located in kf, at the location (the
  // prediction is in the edge already); else (a loop the robust kernel took for an outlier) it
  // stays at its prediction, as a keyframe made for such a loop stayed where the odometry put it.
  // The location enters twice, in the edge and in the reference, should the next keyframe be
  // made from this reference rather than from a later re-anchoring: a keyframe made for the loop
  // avoided that, and kept a vertex and a mapper scan per lap
  // (docs/decisions/2026-12-07-loops-closed-without-a-keyframe.md).
  const Eigen::Isometry3d T_k_predicted = graph_.poses[static_cast<size_t>(kf.id)].inverse() * world_pose(T_odom_camera);
  const Matrix6d located = right_covariance(loop.information);
  const Vector6d error = se3::log(T_k_predicted.inverse() * loop.T_candidate_query);
  const double chi2 = error.dot((predicted + located).ldlt().solve(error));
  if (chi2 <= kChi2Of6Dof99Percent) {
    reference_ = OdometryReference{kf.id, frame.utime, T_odom_camera, frame.T_body_camera, loop.T_candidate_query, located};
    reference_marginal_ = marginal_covariance(graph_, static_cast<int>(kf.id), options_.optimizer.kernel);
    step.reanchored = true;
    step.reanchor_keyframe_id = kf.id;
    ++reanchors_;
  } else {
    carry_reference(frame, T_odom_camera, link, predicted, step);
    reference_marginal_ = marginal_covariance(graph_, static_cast<int>(r), options_.optimizer.kernel);
  }
  return true;
}

bool Slam::reanchor(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                    const std::optional<Matrix6d>& odometry_covariance, const FrameFeatures& features,
                    const sensors::SensorProfile& sensor, SlamStep& step) {
  const CoverageOptions& c = options_.coverage;
  // After an odometry break the estimate is no guide to which keyframes are near.
  if (!gate_by_pose_) return false;
  // Localising only keeps the map as it is; provisional keyframes are outside it (the vehicle
  // started where the map never looked): they are mapped.
  const bool localising = options_.localize_only && provisional_from_ < 0;
  const Eigen::Isometry3d T_world_frame = world_pose(T_odom_camera);
  std::vector<std::pair<double, size_t>> covering;  // (distance in units of the bounds, keyframe)
  // Not placed in the saved map yet: "world" here is the provisional keyframes' own frame.
  for (size_t k = provisional_from_ >= 0 ? static_cast<size_t>(provisional_from_) : 0; k < keyframes_.size(); ++k) {
    const double d = se3::translation_distance(graph_.poses[k], T_world_frame);
    const double a = se3::rotation_distance(graph_.poses[k], T_world_frame);
    // Localisation only: a thinned keyframe still covers its view (the map is not to grow there).
    if (d < c.max_translation_m && a < c.max_rotation_rad && (!keyframes_[k].thinned || localising))
      covering.emplace_back(d / std::max(c.max_translation_m, 1e-9) + a / std::max(c.max_rotation_rad, 1e-9), k);
  }
  std::sort(covering.begin(), covering.end());
  if (static_cast<int>(covering.size()) > c.max_candidates) covering.resize(static_cast<size_t>(c.max_candidates));
  if (covering.empty()) {
    ++coverage_misses_.none_near;
    return false;
  }
  // The frame in the reference's keyframe as the odometry predicts it, and that pose's
  // covariance: the reference's, carried through the odometry since (adjoint), plus the
  // odometry's own.
  const Eigen::Isometry3d T_ref_frame = reference_.T_odom_camera.inverse() * T_odom_camera;
  const Matrix6d Ad = se3::adjoint(T_ref_frame.inverse());
  const Matrix6d predicted =
      Ad * reference_.covariance * Ad.transpose() +
      right_covariance(odometry_edge_information(T_ref_frame, options_.odometry, link, odometry_covariance));
  if (static_cast<int>(features.num_points()) < options_.verification.min_inliers) {
    // No verification can pass (it needs min_inliers points with depth): a keyframe here would
    // never be matched, and the covering keyframes hold the view. The frame becomes the
    // reference where the odometry puts it, so the next try comes after the keyframe spacing
    // rather than at every frame of a blank stretch.
    ++coverage_misses_.featureless;
    carry_reference(frame, T_odom_camera, link, predicted, step);
    return true;
  }
  for (const auto& [distance, k] : covering) {
    const Keyframe& kf = keyframes_[k];
    if (kf.thinned) continue;
    // The seed depends on the pair only, so that a replay verifies identically.
    const uint64_t seed = static_cast<uint64_t>(kf.id) * 1000003u + static_cast<uint64_t>(frame.utime);
    // Located against a prediction it must match within max_correction: the inliers' precision
    // (the rotation test) is what counts here, not their size, which refused close-up views of
    // a wall (docs/decisions/2026-12-05-reanchoring-judged-by-precision-and-a-feature-budget.md).
    VerificationOptions verification = loop_verification(options_.verification, kf.sensor, sensor);
    verification.min_spread_m = 0.0;
    const LoopConstraint located = verify_loop(features, kf.features, verification, seed);
    if (!located.accepted) continue;
    // The frame where the features put it, against where the map and the odometry expect it:
    // a small difference is the drift since the reference; a large one is a loop to close.
    const Eigen::Isometry3d T_expected_located =
        (graph_.poses[k].inverse() * T_world_frame).inverse() * located.T_candidate_query;
    if (T_expected_located.translation().norm() > c.max_correction_m ||
        so3::angle(T_expected_located.linear()) > c.max_correction_rad) {
      step.loop = located;
      if (!localising) {
        // A loop to close: by an edge between keyframes the map has (CoverageOptions::
        // close_loops_in_place), else through a new keyframe.
        if (close_loop_in_place(frame, T_odom_camera, link, kf, predicted, located, step)) return true;
        ++coverage_misses_.too_far;
        return false;
      }
      ++coverage_misses_.too_far;
      // Localisation only: the map stays as it is. One view placing the frame far from its
      // estimate may be a wrong place, so the frame is carried at its prediction and the next
      // frames are relocalised (with confirmation; this placement is the first hypothesis) for
      // at most max_span_s, after which the estimate carries on (the vehicle may have left).
      carry_reference(frame, T_odom_camera, link, predicted, step);
      accept_placement(frame, T_odom_camera, kf, located);  // at most one: never enough alone
      localized_ = false;
      lost_since_utime_ = frame.utime;
      return true;
    }
    // The frame in keyframe k twice: predicted (the reference and the odometry since, with
    // their covariances) and located (the features'); the reference becomes their fusion, so
    // a precise odometry is not replaced by a coarser location, and drift is still bounded.
    const Eigen::Isometry3d T_k_predicted = graph_.poses[k].inverse() * T_world_frame;
    const Matrix6d measured = right_covariance(located.information);
    const Matrix6d gain = predicted * (predicted + measured).inverse();
    const Eigen::Isometry3d T_k_frame = T_k_predicted * se3::exp(gain * se3::log(T_expected_located));
    Matrix6d fused = (Matrix6d::Identity() - gain) * predicted;
    fused = 0.5 * (fused + fused.transpose());
    const auto marginal = marginal_covariance(graph_, static_cast<int>(k), options_.optimizer.kernel);
    reference_ = OdometryReference{kf.id, frame.utime, T_odom_camera, frame.T_body_camera, T_k_frame, fused};
    reference_marginal_ = marginal;
    step.reanchored = true;
    step.reanchor_keyframe_id = kf.id;
    step.loop = located;
    ++reanchors_;
    return true;
  }
  // Localisation only, a view of the map that does not verify adds no keyframe either; in
  // mapping, none does while the prediction is certain and local (CoverageOptions).
  std::vector<size_t> covering_keyframes;
  for (const auto& entry : covering) covering_keyframes.push_back(entry.second);
  if (localising || carriable(covering_keyframes, predicted)) {
    ++coverage_misses_.unverified_carried;
  } else if (static_cast<int>(features.num_points()) < c.min_points_to_verify) {
    // A keyframe made of so few points would hardly ever verify either (CoverageOptions::
    // min_points_to_verify): it would add a view the map cannot use, one every lap over a
    // blank wall. Carried, the odometry goes on to a frame that can be located, or that, too
    // far from its estimate, closes the loop through a keyframe of its own.
    ++coverage_misses_.few_points_carried;
  } else {
    ++coverage_misses_.not_verified;
    return false;
  }
  carry_reference(frame, T_odom_camera, link, predicted, step);
  return true;
}

bool Slam::carriable(const std::vector<size_t>& covering, const Matrix6d& predicted) const {
  const CoverageOptions& c = options_.coverage;
  const double sigmas = c.carry_within_sigmas;
  if (!(sigmas > 0.0)) return false;
  // The prediction is relative to the reference's keyframe, while "covered" and the correction
  // bound are judged against the covering keyframes in the world. The two agree only where the
  // graph relates them by one odometry edge at most (the reference's keyframe covers the frame,
  // or is an odometry neighbour of one that does). Anywhere else (a revisit after a long way
  // round, where the world estimate may have drifted) the frame is a keyframe and its loop is
  // searched for.
  const int reference = static_cast<int>(reference_.keyframe_id);
  const auto neighbour = [&](size_t k) {
    if (static_cast<int>(k) == reference) return true;
    for (const auto& e : graph_.edges)
      if (e.kind == EdgeKind::kOdometry && ((e.from == reference && e.to == static_cast<int>(k)) ||
                                            (e.to == reference && e.from == static_cast<int>(k))))
        return true;
    return false;
  };
  if (std::none_of(covering.begin(), covering.end(), neighbour)) return false;
  // Written so that a covariance that is not finite is never certain.
  return sigmas * largest_sigma(predicted.topLeftCorner<3, 3>()) <= c.max_correction_m &&
         sigmas * largest_sigma(predicted.bottomRightCorner<3, 3>()) <= c.max_correction_rad;
}

void Slam::carry_reference(const RgbdFrame& frame, const Eigen::Isometry3d& T_odom_camera, OdometryLink link,
                           const Matrix6d& predicted, SlamStep& step) {
  const Eigen::Isometry3d T_ref_frame = reference_.T_odom_camera.inverse() * T_odom_camera;
  reference_ = OdometryReference{reference_.keyframe_id,
                                 frame.utime,
                                 T_odom_camera,
                                 frame.T_body_camera,
                                 reference_.T_keyframe_camera * T_ref_frame,
                                 predicted,
                                 weaker(reference_.link, link)};
  step.carried = true;
}

}  // namespace kestrel::slam
