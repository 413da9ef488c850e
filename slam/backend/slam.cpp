#include "slam/backend/slam.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

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
  require(o.loops.min_age_s >= 0.0, "loops.min_age_s must be >= 0");
  require(o.loops.max_candidates >= 1, "loops.max_candidates must be >= 1");
  const OdometryNoise& n = o.odometry;
  require(n.translation_floor_m > 0.0 && n.rotation_floor_rad > 0.0, "odometry noise floors must be > 0");
  require(n.translation_per_m >= 0.0 && n.rotation_per_rad >= 0.0 && n.rotation_per_m >= 0.0,
          "odometry noise rates must be >= 0");
  require(n.break_translation_m > 0.0 && n.break_rotation_rad > 0.0, "odometry break noise must be > 0");
  require(n.bridge_translation_m > 0.0 && n.bridge_rotation_rad > 0.0, "odometry bridge noise must be > 0");
  require(n.reported_translation_floor_m > 0.0 && n.reported_rotation_floor_rad > 0.0,
          "odometry reported-covariance floors must be > 0");
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

// The same from the odometry's own covariance of a right perturbation [rho; phi] of T_prev_cur
// (the measurement Z of the edge): the error of Z * Exp(xi) is [rho; phi / 2] to first order.
Matrix6d reported_odometry_information(const Matrix6d& covariance, const OdometryNoise& n) {
  Matrix6d cov = covariance;
  cov.diagonal().head<3>().array() += n.reported_translation_floor_m * n.reported_translation_floor_m;
  cov.diagonal().tail<3>().array() += n.reported_rotation_floor_rad * n.reported_rotation_floor_rad;
  Matrix6d S = Matrix6d::Identity();
  S.bottomRightCorner<3, 3>() *= 0.5;
  const Matrix6d info = (S * cov * S).inverse();
  return 0.5 * (info + info.transpose());
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

Slam::Slam(const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary)
    : options_(options), vocabulary_(std::move(vocabulary)), extractor_(options.features) {
  check_options(options_);
  reset();
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
  newest_covariance_.reset();
}

void Slam::change_world(const Eigen::Isometry3d& T_new_world) {
  if (!se3::is_valid(T_new_world, 1e-6)) throw std::invalid_argument("slam: change_world needs a rigid transform");
  for (auto& T : graph_.poses) T = T_new_world * T;
  ++revision_;
}

bool Slam::wants_keyframe(const Eigen::Isometry3d& T_odom_camera, OdometryLink link) const {
  if (!T_odom_camera.matrix().allFinite()) return false;
  // After a restart the earlier keyframe's odometry ends: the edge must span only the gap.
  if (keyframes_.empty() || link != OdometryLink::kContinuous) return true;
  const Eigen::Isometry3d T_last_cur = keyframes_.back().T_odom_camera.inverse() * T_odom_camera;
  return T_last_cur.translation().norm() >= options_.keyframes.min_translation_m ||
         so3::angle(T_last_cur.linear()) >= options_.keyframes.min_rotation_rad;
}

Eigen::Isometry3d Slam::world_pose(const Eigen::Isometry3d& T_odom_camera) const {
  if (keyframes_.empty()) return T_odom_camera;
  return graph_.poses.back() * keyframes_.back().T_odom_camera.inverse() * T_odom_camera;
}

void Slam::add_odometry_edge(const Keyframe& previous, const Keyframe& current, OdometryLink link,
                             const std::optional<Matrix6d>& covariance) {
  // After a break the odometry poses of the two are unrelated: assume no motion, weakly.
  const Eigen::Isometry3d T_prev_cur = link == OdometryLink::kBroken
                                           ? Eigen::Isometry3d::Identity()
                                           : previous.T_odom_camera.inverse() * current.T_odom_camera;
  graph_.add_edge(static_cast<int>(previous.id), static_cast<int>(current.id), T_prev_cur,
                  odometry_edge_information(T_prev_cur, options_.odometry, link, covariance), EdgeKind::kOdometry);
  gate_information_.resize(graph_.edges.size() - 1, Matrix6d::Identity());
  gate_information_.push_back(odometry_information(T_prev_cur, options_.odometry, link));
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
  have_frame_ = true;
  last_utime_ = frame.utime;
  if (odometry_broken) gate_by_pose_ = false;
  SlamStep step;
  if (!wants_keyframe(T_odom_camera, link)) return step;

  Keyframe kf;
  kf.id = static_cast<int64_t>(keyframes_.size());
  kf.utime = frame.utime;
  kf.T_odom_camera = T_odom_camera;
  kf.T_body_camera = frame.T_body_camera;
  kf.T_camera_depth = motion.T_rgb_depth();
  kf.link = keyframes_.empty() ? OdometryLink::kContinuous : link;
  kf.sensor = sensor;
  kf.features = extractor_.extract(frame, motion);
  const Eigen::Isometry3d T_world_camera =
      keyframes_.empty() ? T_odom_camera
                         : (odometry_broken ? graph_.poses.back() : world_pose(T_odom_camera));
  graph_.add_vertex(kf.id, T_world_camera, keyframes_.empty());
  if (!keyframes_.empty()) add_odometry_edge(keyframes_.back(), kf, link, odometry_covariance);
  keyframes_.push_back(std::move(kf));
  step.keyframe = true;
  step.keyframe_id = keyframes_.back().id;
  step = close_loop(std::move(step));
  places_->add(keyframes_.back().features.descriptors);
  return step;
}

SlamStep Slam::close_loop(SlamStep step) {
  const Keyframe& query = keyframes_.back();
  const Eigen::Isometry3d& T_world_query = graph_.poses.back();
  const auto min_age_us = static_cast<int64_t>(std::llround(options_.loops.min_age_s * 1e6));
  const LoopSearchOptions& lo = options_.loops;
  const bool gate = gate_by_pose_ && lo.max_distance_m > 0.0;
  auto allowed = [&](int entry) {
    const Keyframe& k = keyframes_[static_cast<size_t>(entry)];
    if (k.utime > query.utime - min_age_us) return false;
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
    if (gate && !check_loop_against_odometry(graph_, static_cast<int>(earlier.id), static_cast<int>(query.id),
                                             step.loop.T_candidate_query, options_.loop_consistency,
                                             &gate_information_)
                     .consistent) {
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
    newest_covariance_ = marginal_covariance(graph_, static_cast<int>(query.id), options_.optimizer.kernel);
    ++revision_;
    gate_by_pose_ = true;
    break;  // the paper stops at the first success
  }
  return step;
}

}  // namespace kestrel::slam
