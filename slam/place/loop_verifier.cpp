#include "slam/place/loop_verifier.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "common/geometry/align.h"
#include "slam/place/binary_descriptor.h"

namespace kestrel::slam {
namespace {

struct Match {
  int query, candidate;  // feature indices
};

// Ratio-test matches from query to candidate among features with a 3-D point in both: each
// query descriptor's nearest candidate by Hamming distance, if it is near enough and clearly
// nearer than the second nearest (a tie for the nearest never passes, so which of the tied
// is "nearest" does not matter). Brute force, as OpenCV's BFMatcher::knnMatch(k = 2) did, but
// without its per-pair call overhead, which made it most of a SLAM run's time.
std::vector<Match> ratio_matches(const FrameFeatures& query, const FrameFeatures& candidate,
                                 const VerificationOptions& o) {
  std::vector<Match> out;
  if (query.descriptors.rows < 2 || candidate.descriptors.rows < 2) return out;
  const std::vector<Descriptor> queries = to_descriptors(query.descriptors);
  const std::vector<Descriptor> train = to_descriptors(candidate.descriptors);
  for (size_t q = 0; q < queries.size(); ++q) {
    const auto [c, best, second] = nearest_two(queries[q], train);
    if (best > o.max_hamming || best >= o.ratio * second) continue;
    if (query.has_point(q) && candidate.has_point(static_cast<size_t>(c))) out.push_back(Match{static_cast<int>(q), c});
  }
  return out;
}

double tolerance(const VerificationOptions& o, double z_q, double z_c) {
  const double sq = o.depth_noise * z_q * z_q, sc = o.depth_noise * z_c * z_c;
  return o.inlier_floor_m + o.inlier_sigmas * std::sqrt(sq * sq + sc * sc);
}

std::vector<int> inliers_of(const Eigen::Isometry3d& T_q_c, const FrameFeatures& query,
                            const FrameFeatures& candidate, const std::vector<Match>& matches,
                            const VerificationOptions& o) {
  std::vector<int> in;
  for (size_t k = 0; k < matches.size(); ++k) {
    const Eigen::Vector3d& pq = query.points[matches[k].query];
    const Eigen::Vector3d& pc = candidate.points[matches[k].candidate];
    if ((pq - T_q_c * pc).norm() < tolerance(o, pq.z(), pc.z())) in.push_back(static_cast<int>(k));
  }
  return in;
}

std::optional<Eigen::Isometry3d> fit(const FrameFeatures& query, const FrameFeatures& candidate,
                                     const std::vector<Match>& matches, const std::vector<int>& which) {
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(which.size())), dst(3, src.cols());
  for (size_t k = 0; k < which.size(); ++k) {
    src.col(static_cast<Eigen::Index>(k)) = candidate.points[matches[which[k]].candidate];
    dst.col(static_cast<Eigen::Index>(k)) = query.points[matches[which[k]].query];
  }
  return align_rigid(src, dst);
}

// Standard deviation of the inlier points along their second principal axis: small when they
// lie on a line (the rotation about it is then undetermined).
double spread(const FrameFeatures& query, const std::vector<Match>& matches, const std::vector<int>& which) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int k : which) mean += query.points[matches[k].query];
  mean /= static_cast<double>(which.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const int k : which) {
    const Eigen::Vector3d d = query.points[matches[k].query] - mean;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(which.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(eig.eigenvalues()(1), 0.0));
}

LoopConstraint reject(LoopConstraint c, std::string why) {
  c.accepted = false;
  c.reason = std::move(why);
  return c;
}

}  // namespace

Matrix6d edge_information(const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance_right_T_a_b) {
  // T_a_b' = T_a_b (+) d  =>  Z' = T_a_b'^-1 = Z (+) nu with nu = -Ad(T_a_b) d; the g2o error of
  // a right perturbation nu = [rho; phi] is -[rho; phi / 2] to first order.
  const Matrix6d A = se3::adjoint(T_a_b);
  const Matrix6d cov_nu = A * covariance_right_T_a_b * A.transpose();
  Matrix6d S = Matrix6d::Identity();
  S.bottomRightCorner<3, 3>() *= 0.5;
  const Matrix6d cov_e = S * cov_nu * S;
  Matrix6d info = cov_e.inverse();
  return 0.5 * (info + info.transpose());
}

VerificationOptions loop_verification(VerificationOptions options, const sensors::SensorProfile& a,
                                      const sensors::SensorProfile& b) {
  for (const sensors::SensorProfile* p : {&a, &b})
    if (p->slam.loop_rotation_floor_rad)
      options.rotation_sigma_floor_rad = std::max(options.rotation_sigma_floor_rad, *p->slam.loop_rotation_floor_rad);
  return options;
}

LoopConstraint verify_loop(const FrameFeatures& query, const FrameFeatures& candidate,
                           const VerificationOptions& o, uint64_t seed) {
  LoopConstraint c;
  const std::vector<Match> matches = ratio_matches(query, candidate, o);
  c.matches = static_cast<int>(matches.size());
  if (c.matches < o.min_inliers) {
    return reject(c, std::to_string(c.matches) + " matches with depth pass the ratio test");
  }

  // RANSAC on minimal sets of three 3-D correspondences.
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, matches.size() - 1);
  std::vector<int> best;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    const size_t a = pick(rng), b = pick(rng), d = pick(rng);
    if (a == b || b == d || a == d) continue;
    const auto T = fit(query, candidate, matches, {static_cast<int>(a), static_cast<int>(b), static_cast<int>(d)});
    if (!T) continue;
    std::vector<int> in = inliers_of(*T, query, candidate, matches, o);
    if (in.size() > best.size()) best.swap(in);
  }
  if (static_cast<int>(best.size()) < o.min_inliers) {
    c.inliers = static_cast<int>(best.size());
    return reject(c, "RANSAC found " + std::to_string(best.size()) + " inliers");
  }
  // Refit on the inliers and take the consensus of the refit.
  auto T_q_c = fit(query, candidate, matches, best);
  if (!T_q_c) return reject(c, "inliers are degenerate");
  best = inliers_of(*T_q_c, query, candidate, matches, o);
  c.inliers = static_cast<int>(best.size());
  if (c.inliers < o.min_inliers) return reject(c, "refit kept " + std::to_string(c.inliers) + " inliers");
  if (c.inliers < o.min_inlier_fraction * c.matches) {
    return reject(c, std::to_string(c.inliers) + " of " + std::to_string(c.matches) + " matches agree");
  }
  c.spread_m = spread(query, matches, best);
  if (o.min_spread_m > 0.0 && c.spread_m < o.min_spread_m) {
    return reject(c, "inliers do not spread in space");
  }

  // Two-frame bundle adjustment of the relative pose.
  std::vector<TwoViewObservation> observations;
  for (const int k : best) {
    const auto& m = matches[k];
    TwoViewObservation ob;
    ob.pixel_a = Eigen::Vector2d(query.keypoints[m.query].pt.x, query.keypoints[m.query].pt.y);
    ob.pixel_b = Eigen::Vector2d(candidate.keypoints[m.candidate].pt.x, candidate.keypoints[m.candidate].pt.y);
    ob.depth_a = query.points[m.query].z();
    ob.depth_b = candidate.points[m.candidate].z();
    observations.push_back(ob);
  }
  const TwoViewResult ba = adjust_two_views(query.camera, candidate.camera, observations, *T_q_c, o.adjustment);
  if (!ba.ok) return reject(c, "bundle adjustment failed");
  double sum = 0.0;
  c.inliers = 0;
  for (const double e : ba.pixel_errors) {
    if (e > o.max_pixel_error) continue;
    ++c.inliers;
    sum += e * e;
  }
  if (c.inliers < o.min_inliers) {
    return reject(c, "after adjustment " + std::to_string(c.inliers) + " inliers reproject within " +
                         std::to_string(o.max_pixel_error) + " px");
  }
  c.rms_px = std::sqrt(sum / c.inliers);
  if (c.rms_px > o.max_rms_px) return reject(c, "reprojection error " + std::to_string(c.rms_px) + " px");

  // Inliers near one line (a row of features on an edge, a stripe of texture) leave the rotation
  // about it to the noise; the adjustment's covariance says so whatever the range and the count.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rotation(ba.covariance.bottomRightCorner<3, 3>(),
                                                               Eigen::EigenvaluesOnly);
  const double rotation_sigma = std::sqrt(std::max(rotation.eigenvalues()(2), 0.0));
  if (!(rotation_sigma <= o.max_rotation_sigma_rad)) {
    return reject(c, "the inliers leave the rotation " + std::to_string(rotation_sigma * 180.0 / kPi) +
                         " degrees uncertain about one axis");
  }

  Matrix6d cov = ba.covariance;
  cov.topLeftCorner<3, 3>().diagonal().array() += o.translation_sigma_floor_m * o.translation_sigma_floor_m;
  cov.bottomRightCorner<3, 3>().diagonal().array() += o.rotation_sigma_floor_rad * o.rotation_sigma_floor_rad;
  c.T_candidate_query = ba.T_a_b.inverse();
  c.information = edge_information(ba.T_a_b, cov);
  if (!c.information.allFinite()) return reject(c, "singular covariance");
  c.accepted = true;
  return c;
}

}  // namespace kestrel::slam
