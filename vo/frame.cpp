#include "vo/frame.h"

#include <algorithm>
#include <cmath>

namespace kestrel::vo {

void FeatureGrid::build(const std::vector<Feature>& features, int begin, int end, int width,
                        int height, int cell_px) {
  features_ = &features;
  cell_ = std::max(1, cell_px);
  cols_ = std::max(1, (width + cell_ - 1) / cell_);
  rows_ = std::max(1, (height + cell_ - 1) / cell_);
  const size_t n = static_cast<size_t>(cols_ * rows_);
  cell_start_.assign(n + 1, 0);
  auto cell_of = [&](const Feature& f) {
    const int c = std::clamp(static_cast<int>(f.u) / cell_, 0, cols_ - 1);
    const int r = std::clamp(static_cast<int>(f.v) / cell_, 0, rows_ - 1);
    return static_cast<size_t>(r * cols_ + c);
  };
  for (int i = begin; i < end; ++i) ++cell_start_[cell_of(features[static_cast<size_t>(i)]) + 1];
  for (size_t c = 0; c < n; ++c) cell_start_[c + 1] += cell_start_[c];
  index_.resize(static_cast<size_t>(end - begin));
  std::vector<int>& next = cell_start_;  // advanced while filling, shifted back below
  for (int i = begin; i < end; ++i) index_[static_cast<size_t>(next[cell_of(features[static_cast<size_t>(i)])]++)] = i;
  for (size_t c = n; c > 0; --c) next[c] = next[c - 1];
  next[0] = 0;
}

void describe_features(Frame& frame, int window_size, float search_radius_level0_px) {
  frame.descriptors.reset(window_size);
  for (const Feature& f : frame.features) {
    frame.descriptors.add(frame.pyramid.level(f.level), static_cast<int>(f.u),
                          static_cast<int>(f.v));
  }
  for (int level = 0; level < frame.pyramid.levels(); ++level) {
    const cv::Mat& image = frame.pyramid.level(level);
    const float radius = search_radius_level0_px / static_cast<float>(1 << level);
    const int cell = std::max(8, static_cast<int>(std::ceil(radius)));
    frame.grids[static_cast<size_t>(level)].build(frame.features,
                                                  frame.level_begin[static_cast<size_t>(level)],
                                                  frame.level_begin[static_cast<size_t>(level + 1)],
                                                  image.cols, image.rows, cell);
  }
}

}  // namespace kestrel::vo
