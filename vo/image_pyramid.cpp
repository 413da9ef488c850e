#include "vo/image_pyramid.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace kestrel::vo {

void ImagePyramid::build(const cv::Mat& image, int levels, double blur_sigma) {
  if (levels < 1) throw std::invalid_argument("ImagePyramid: levels must be >= 1");
  levels_.resize(static_cast<size_t>(levels));
  const cv::Mat* grey = &image;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, grey_, cv::COLOR_RGB2GRAY);
    grey = &grey_;
  } else if (image.type() != CV_8UC1) {
    throw std::invalid_argument("ImagePyramid: image must be CV_8UC3 or CV_8UC1");
  }
  if (blur_sigma > 0.0) {
    // Radius ceil(2 sigma): a 5x5 kernel for sigma 0.85, which drops only the far tail; OpenCV's
    // 8-bit path for it is fixed-point and vectorised.
    const int k = 2 * static_cast<int>(std::ceil(2.0 * blur_sigma)) + 1;
    cv::GaussianBlur(*grey, levels_[0], cv::Size(k, k), blur_sigma, blur_sigma,
                     cv::BORDER_REFLECT_101);
  } else {
    grey->copyTo(levels_[0]);
  }
  for (size_t i = 1; i < levels_.size(); ++i) {
    cv::pyrDown(levels_[i - 1], levels_[i]);
  }
}

void ImagePyramid::swap(ImagePyramid& other) noexcept {
  cv::swap(grey_, other.grey_);
  levels_.swap(other.levels_);
}

}  // namespace kestrel::vo
