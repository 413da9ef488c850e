#include "vo/feature_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::vo {

void FastThresholdController::update(int num_detected, int image_pixels) {
  if (!options_.adaptive) return;
  const double target = image_pixels / options_.target_pixels_per_feature;
  const double step = options_.adaptive_gain * (num_detected - target);
  threshold_ = std::clamp(threshold_ + static_cast<int>(std::lround(step)), options_.min_threshold,
                          options_.max_threshold);
}

int border_margin(const MatchOptions& match) {
  // Half the patch, one more for the gradients of the subpixel refinement, and the shift it
  // may make.
  return match.window_size / 2 + 1 + static_cast<int>(std::ceil(match.max_subpixel_shift_px));
}

void FeatureDetector::detect(const cv::Mat& rgb, int threshold, Frame& frame) {
  if (pyramid_.levels < 1 || pyramid_.levels > kMaxLevels)
    throw std::invalid_argument("FeatureDetector: pyramid levels must be 1..4");
  frame.pyramid.build(rgb, pyramid_.levels, pyramid_.blur_sigma);
  frame.features.clear();
  frame.level_begin.fill(0);
  frame.num_detected = 0;
  frame.fast_threshold = threshold;
  const int margin = border_margin(match_);

  for (int level = 0; level < pyramid_.levels; ++level) {
    const cv::Mat& image = frame.pyramid.level(level);
    frame.level_begin[static_cast<size_t>(level)] = static_cast<int>(frame.features.size());
    detect_fast9(image, threshold, true, corners_, fast_scratch_);
    frame.num_detected += static_cast<int>(corners_.size());
    corners_.erase(std::remove_if(corners_.begin(), corners_.end(),
                                  [&](const FastCorner& c) {
                                    return c.x < margin || c.y < margin ||
                                           c.x >= image.cols - margin || c.y >= image.rows - margin;
                                  }),
                   corners_.end());
    if (bucket_.enabled) bucket(corners_, image.cols, image.rows);
    for (const FastCorner& c : corners_) {
      Feature f;
      f.u = c.x;
      f.v = c.y;
      f.u0 = to_level0(f.u, level);
      f.v0 = to_level0(f.v, level);
      f.level = static_cast<int16_t>(level);
      f.score = c.score;
      frame.features.push_back(f);
    }
  }
  for (int level = pyramid_.levels; level <= kMaxLevels; ++level)
    frame.level_begin[static_cast<size_t>(level)] = static_cast<int>(frame.features.size());
  frame.num_bucketed = static_cast<int>(frame.features.size());
}

void FeatureDetector::bucket(std::vector<FastCorner>& corners, int width, int height) {
  const int nx = (width + bucket_.width_px - 1) / bucket_.width_px;
  const int ny = (height + bucket_.height_px - 1) / bucket_.height_px;
  const size_t nb = static_cast<size_t>(nx * ny);
  auto bucket_of = [&](const FastCorner& c) {
    return static_cast<size_t>((c.y / bucket_.height_px) * nx + c.x / bucket_.width_px);
  };
  // Counting sort by bucket keeps raster order inside each bucket, so ties break the same way
  // on every run.
  bucket_count_.assign(nb + 1, 0);
  for (const FastCorner& c : corners) ++bucket_count_[bucket_of(c) + 1];
  for (size_t b = 0; b < nb; ++b) bucket_count_[b + 1] += bucket_count_[b];
  bucketed_.resize(corners.size());
  {
    std::vector<int>& next = bucket_count_;  // advanced as corners are placed, restored below
    for (const FastCorner& c : corners) bucketed_[static_cast<size_t>(next[bucket_of(c)]++)] = c;
    for (size_t b = nb; b > 0; --b) next[b] = next[b - 1];
    next[0] = 0;
  }
  corners.clear();
  const auto stronger = [](const FastCorner& a, const FastCorner& b) {
    if (a.score != b.score) return a.score > b.score;
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  };
  for (size_t b = 0; b < nb; ++b) {
    auto first = bucketed_.begin() + bucket_count_[b];
    auto last = bucketed_.begin() + bucket_count_[b + 1];
    if (last - first > bucket_.max_per_bucket) {
      std::nth_element(first, first + bucket_.max_per_bucket, last, stronger);
      last = first + bucket_.max_per_bucket;
    }
    corners.insert(corners.end(), first, last);
  }
  // Back to raster order, which the rest of the pipeline does not need but tests can rely on.
  std::sort(corners.begin(), corners.end(), [](const FastCorner& a, const FastCorner& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
}

}  // namespace kestrel::vo
