#pragma once
// The grey-level Gaussian pyramid a frame is described by: level 0 is the grey image blurred
// with sigma = PyramidOptions::blur_sigma, each next level halves the previous one (5-tap
// Gaussian and decimation). Extra coarse levels, beyond the feature levels, serve the rotation
// prior, which works on heavily down-sampled images.
//
// The filters are kestrel's own integer, separable, single-threaded loops (image_pyramid.cpp),
// not OpenCV's, whose thread pool would hide work from a one-core measurement.
//
// Invariants: level(i) is CV_8UC1 of size ceil(size / 2^i); buffers are reused from one build()
// to the next when the image size does not change, so a steady stream allocates nothing.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace kestrel::vo {

class ImagePyramid {
 public:
  /// Builds `levels` levels (>= 1) from an 8-bit RGB (CV_8UC3, R,G,B) or grey (CV_8UC1) image.
  void build(const cv::Mat& image, int levels, double blur_sigma);

  int levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int i) const { return levels_[static_cast<size_t>(i)]; }

  /// Exchanges contents with `other` (buffers included), for frame recycling.
  void swap(ImagePyramid& other) noexcept;

 private:
  void blur(const cv::Mat& grey, double sigma, cv::Mat& out);

  cv::Mat grey_;
  std::vector<cv::Mat> levels_;
  std::vector<int> kernel_;
  double kernel_sigma_ = -1.0;  // the sigma kernel_ was made for
  std::vector<uint16_t> row_, column_;  // filter scratch
};

/// R,G,B (CV_8UC3) -> grey (CV_8UC1), (77 R + 150 G + 29 B + 128) >> 8; SSE2 where available.
void rgb_to_grey(const cv::Mat& rgb, cv::Mat& grey);
/// The same with the portable scalar loop only (the reference the SSE2 path is tested against).
void rgb_to_grey_scalar(const cv::Mat& rgb, cv::Mat& grey);

/// Integer Gaussian weights of radius max(1, ceil(2 sigma)) summing to 64.
void gaussian_kernel_64(double sigma, std::vector<int>& weights);

/// Halves `in` like cv::pyrDown (5-tap 1-4-6-4-1 Gaussian, reflect-101 border, size
/// ceil(size / 2)); `row` is scratch.
void half_size(const cv::Mat& in, cv::Mat& out, std::vector<uint16_t>& row);
/// The same with the portable scalar loops only (half_size's SSE2 path equals it exactly).
void half_size_scalar(const cv::Mat& in, cv::Mat& out, std::vector<uint16_t>& row);

/// Pixel coordinates of level `level` mapped to level 0 (pixel centres, not corners, scale).
inline float to_level0(float x, int level) {
  const float s = static_cast<float>(1 << level);
  return (x + 0.5f) * s - 0.5f;
}
/// Level-0 pixel coordinates mapped to level `level`.
inline float from_level0(float x, int level) {
  const float s = static_cast<float>(1 << level);
  return (x + 0.5f) / s - 0.5f;
}

}  // namespace kestrel::vo
