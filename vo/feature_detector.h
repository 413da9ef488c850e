#pragma once
// Feature detection on a frame's pyramid: FAST-9 on every level, the adaptive threshold
// (a proportional controller on the number of detections), and bucketing (the strongest
// features of each cell, so that they spread over the image).
//
// Invariant: detect() leaves frame.features sorted by level with level_begin set, every feature
// far enough from its level's border for a descriptor patch and its subpixel refinement
// (border_margin()). Depth is attached afterwards (depth_lookup.h).

#include <vector>

#include "vo/fast.h"
#include "vo/frame.h"
#include "vo/options.h"

namespace kestrel::vo {

/// Keeps the number of FAST detections near a target by moving the threshold in proportion to
/// the surplus: t += gain * (detected - target), clamped to [min, max].
class FastThresholdController {
 public:
  explicit FastThresholdController(const FastOptions& options) : options_(options) { reset(); }
  int threshold() const { return threshold_; }
  void update(int num_detected, int image_pixels);
  void reset() { threshold_ = options_.threshold; }

 private:
  FastOptions options_;
  int threshold_ = 20;
};

/// Margin, in level pixels, a feature keeps from the border of its level.
int border_margin(const MatchOptions& match);

class FeatureDetector {
 public:
  FeatureDetector(const PyramidOptions& pyramid, const BucketOptions& bucket,
                  const MatchOptions& match)
      : pyramid_(pyramid), bucket_(bucket), match_(match) {}

  /// Builds the pyramid of `rgb` (CV_8UC3 R,G,B or CV_8UC1) into `frame` and detects its
  /// features with FAST threshold `threshold`.
  void detect(const cv::Mat& rgb, int threshold, Frame& frame);

 private:
  void bucket(std::vector<FastCorner>& corners, int width, int height);

  PyramidOptions pyramid_;
  BucketOptions bucket_;
  MatchOptions match_;
  FastScratch fast_scratch_;
  std::vector<FastCorner> corners_;
  std::vector<int> bucket_count_;
  std::vector<FastCorner> bucketed_;
};

}  // namespace kestrel::vo
