#pragma once
// Matching features of a reference frame to the current frame: for each reference feature,
// the current features of the same pyramid level inside a window around its predicted
// position are compared by descriptor SAD; a match must be the best for both of its features
// (mutual consistency) and is then refined to subpixel precision in the current image.
//
// Invariant: each reference and each current feature is in at most one match; matches come out
// ordered by reference feature.

#include <Eigen/Core>
#include <vector>

#include "vo/frame.h"
#include "sensors/lens.h"
#include "vo/options.h"

namespace kestrel::vo {

struct Match {
  int ref = -1;                       ///< index of the reference frame's feature
  int cur = -1;                       ///< index of the current frame's feature
  int sad = 0;
  Eigen::Vector2f cur_ideal{0, 0};    ///< current feature's refined ideal level-0 pixel
  Eigen::Vector3f cur_point{0, 0, 0}; ///< current feature's point on the refined ray
};

class Matcher {
 public:
  /// `predicted[i]`: where reference feature i should appear in the current image, raw level-0
  /// pixels (non-finite: not expected in view). Replaces `matches`.
  void match(const Frame& ref, const Frame& cur, const std::vector<Eigen::Vector2f>& predicted,
             const sensors::Lens& lens, const MatchOptions& options, std::vector<Match>& matches);

 private:
  std::vector<int> best_cur_, best_ref_;
  std::vector<int> best_cur_sad_, best_ref_sad_;
};

}  // namespace kestrel::vo
