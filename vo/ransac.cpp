#include "vo/ransac.h"

#include <algorithm>
#include <numeric>
#include <optional>
#include <random>

#include "common/geometry/align.h"

namespace kestrel::vo {
namespace {

std::optional<Eigen::Isometry3f> hypothesis(const std::vector<Eigen::Vector3f>& ref,
                                            const std::vector<Eigen::Vector3f>& cur,
                                            std::mt19937_64& rng) {
  const int n = static_cast<int>(ref.size());
  std::uniform_int_distribution<int> pick(0, n - 1);
  int i = pick(rng), j = pick(rng), k = pick(rng);
  if (i == j || j == k || i == k) return std::nullopt;
  Eigen::Matrix3Xd src(3, 3), dst(3, 3);
  src << cur[static_cast<size_t>(i)].cast<double>(), cur[static_cast<size_t>(j)].cast<double>(),
      cur[static_cast<size_t>(k)].cast<double>();
  dst << ref[static_cast<size_t>(i)].cast<double>(), ref[static_cast<size_t>(j)].cast<double>(),
      ref[static_cast<size_t>(k)].cast<double>();
  const auto T = align_rigid(src, dst);
  if (!T) return std::nullopt;
  return T->cast<float>();
}

}  // namespace

std::vector<int> ransac_inliers(const std::vector<Eigen::Vector3f>& ref_points,
                                const std::vector<Eigen::Vector3f>& cur_points,
                                const RansacOptions& options, uint64_t seed) {
  std::vector<int> inliers;
  const int n = static_cast<int>(ref_points.size());
  if (n < 3) return inliers;
  std::mt19937_64 rng(seed);
  const float t2 = options.threshold_m * options.threshold_m;
  auto is_inlier = [&](const Eigen::Isometry3f& T, size_t i) {
    return (T * cur_points[i] - ref_points[i]).squaredNorm() < t2;
  };

  std::vector<Eigen::Isometry3f> hyps;
  hyps.reserve(static_cast<size_t>(options.hypotheses));
  // A degenerate sample is drawn again, a bounded number of times.
  for (int tries = 0; static_cast<int>(hyps.size()) < options.hypotheses && tries < 4 * options.hypotheses; ++tries) {
    if (auto T = hypothesis(ref_points, cur_points, rng)) hyps.push_back(*T);
  }
  if (hyps.empty()) return inliers;

  Eigen::Isometry3f best = hyps.front();
  if (!options.preemptive) {
    int best_count = -1;
    for (const auto& T : hyps) {
      int count = 0;
      for (size_t i = 0; i < ref_points.size(); ++i) count += is_inlier(T, i);
      if (count > best_count) {
        best_count = count;
        best = T;
      }
    }
  } else {
    // Breadth-first scoring: every surviving hypothesis scores the next block of observations
    // (in random order); after each block only the better half goes on.
    std::vector<int> order(static_cast<size_t>(n));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<int> score(hyps.size(), 0);
    std::vector<int> alive(hyps.size());
    std::iota(alive.begin(), alive.end(), 0);
    size_t next = 0;
    while (alive.size() > 1 && next < order.size()) {
      const size_t end = std::min(order.size(), next + static_cast<size_t>(options.block_size));
      for (int h : alive)
        for (size_t o = next; o < end; ++o)
          score[static_cast<size_t>(h)] += is_inlier(hyps[static_cast<size_t>(h)], static_cast<size_t>(order[o]));
      next = end;
      std::stable_sort(alive.begin(), alive.end(), [&](int a, int b) {
        return score[static_cast<size_t>(a)] > score[static_cast<size_t>(b)];
      });
      alive.resize((alive.size() + 1) / 2);
    }
    best = hyps[static_cast<size_t>(alive.front())];
  }
  for (int i = 0; i < n; ++i)
    if (is_inlier(best, static_cast<size_t>(i))) inliers.push_back(i);
  return inliers;
}

}  // namespace kestrel::vo
