#pragma once
// Inlier detection by sampling, the alternatives Table 1 of the paper compares with the
// max-clique: RANSAC (Fischler & Bolles) and preemptive RANSAC (Nister 2003). A hypothesis is
// the rigid motion of three random matches (absolute orientation); a match is its inlier when
// the motion maps its current point to within `threshold_m` of its reference point.
//
// Invariant: the random sequence is seeded by the caller, so a replay gives the same inliers.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace kestrel::vo {

struct RansacOptions {
  int hypotheses = 500;
  float threshold_m = 0.03f;
  int block_size = 100;  ///< preemptive: observations scored between two halvings
  bool preemptive = false;
};

/// Indices (increasing) of the inliers of the best hypothesis, re-scored over all matches.
std::vector<int> ransac_inliers(const std::vector<Eigen::Vector3f>& ref_points,
                                const std::vector<Eigen::Vector3f>& cur_points,
                                const RansacOptions& options, uint64_t seed);

}  // namespace kestrel::vo
