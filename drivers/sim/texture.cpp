#include "drivers/sim/texture.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::sim {
namespace {

uint32_t pack(const cv::Vec3f& c) {
  uint32_t v = 0;
  for (int i = 0; i < 3; ++i) {
    const float x = std::clamp(c[i], 0.0f, 1.0f) * 255.0f + 0.5f;
    v |= static_cast<uint32_t>(x) << (8 * i);
  }
  return v;
}

}  // namespace

MipTexture::MipTexture(const cv::Mat& rgb) {
  if (rgb.type() != CV_32FC3 || rgb.rows != rgb.cols || rgb.rows <= 0 ||
      (rgb.rows & (rgb.rows - 1)) != 0) {
    throw std::invalid_argument("MipTexture: need a square CV_32FC3 image with a power-of-two side");
  }
  size_ = rgb.rows;
  while ((1 << log2_size_) < size_) ++log2_size_;
  cv::Mat level = rgb;
  for (int l = 0;; ++l) {
    // Rows and columns 0..side-1, then copies of column 0 and row 0 (the wrap).
    const size_t side = static_cast<size_t>(level.rows), stride = side + 1;
    std::vector<uint32_t> packed(stride * stride);
    for (size_t r = 0; r < stride; ++r) {
      const cv::Vec3f* row = level.ptr<cv::Vec3f>(static_cast<int>(r % side));
      for (size_t c = 0; c < stride; ++c) packed[r * stride + c] = pack(row[c % side]);
    }
    levels_.push_back(std::move(packed));
    inverse_scale_.push_back(std::ldexp(1.0f, -l));
    inverse_side_.push_back(1.0f / static_cast<float>(level.rows));
    if (level.rows == 1) {
      const cv::Vec3f m = level.at<cv::Vec3f>(0, 0);
      mean_ = Eigen::Vector3f(m[0], m[1], m[2]).cwiseMax(0.0f).cwiseMin(1.0f);
      break;
    }
    // Box filter of 2x2 blocks; blocks never straddle the wrap because the side is even.
    cv::Mat next(level.rows / 2, level.cols / 2, CV_32FC3);
    for (int r = 0; r < next.rows; ++r) {
      const cv::Vec3f* a = level.ptr<cv::Vec3f>(2 * r);
      const cv::Vec3f* b = level.ptr<cv::Vec3f>(2 * r + 1);
      cv::Vec3f* o = next.ptr<cv::Vec3f>(r);
      for (int c = 0; c < next.cols; ++c)
        o[c] = 0.25f * (a[2 * c] + a[2 * c + 1] + b[2 * c] + b[2 * c + 1]);
    }
    level = next;
  }
}

void MipTexture::add_grey_levels() {
  grey_levels_.clear();
  for (const auto& level : levels_) {
    std::vector<uint8_t> grey(level.size());
    for (size_t i = 0; i < level.size(); ++i) grey[i] = static_cast<uint8_t>(level[i] & 255u);
    grey_levels_.push_back(std::move(grey));
  }
}

std::vector<uint32_t> MipTexture::level(int l) const {
  const size_t side = static_cast<size_t>(size_ >> l), stride = side + 1;
  const std::vector<uint32_t>& stored = levels_[static_cast<size_t>(l)];
  std::vector<uint32_t> out(side * side);
  for (size_t r = 0; r < side; ++r)
    std::copy(stored.begin() + static_cast<std::ptrdiff_t>(r * stride),
              stored.begin() + static_cast<std::ptrdiff_t>(r * stride + side), out.begin() + static_cast<std::ptrdiff_t>(r * side));
  return out;
}

}  // namespace kestrel::sim
