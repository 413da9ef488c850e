#include "drivers/tum/tum_images.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/image/image_io.h"

namespace kestrel::tum {
namespace {

[[noreturn]] void fail(const std::string& path, const ListedAt& at, const std::string& why) {
  throw InputError(at_line(at.list, at.line, path + ": " + why));
}

std::string describe(const cv::Mat& m) {
  const char* depth = m.depth() == CV_8U ? "8-bit" : m.depth() == CV_16U ? "16-bit" : "non-integer";
  return std::string(depth) + ", " + std::to_string(m.channels()) + "-channel";
}

cv::Mat read_image(const std::string& path, int width, int height, const ListedAt& at) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, at, "image file does not exist");
  cv::Mat image;
  try {
    image = image::read_image(path);
  } catch (const InputError& e) {
    // "path: why" from the decoder; the list and line say where the file was named.
    throw InputError(at_line(at.list, at.line, e.what()));
  }
  if (image.cols != width || image.rows != height) {
    fail(path, at, "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                       ", expected " + std::to_string(width) + "x" + std::to_string(height));
  }
  return image;
}

}  // namespace

cv::Mat load_rgb(const std::string& path, int width, int height, const ListedAt& listed_at) {
  cv::Mat bgr = read_image(path, width, height, listed_at);
  if (bgr.type() != CV_8UC3) {
    fail(path, listed_at, "colour image is " + describe(bgr) + ", expected 8-bit, 3-channel");
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

cv::Mat load_depth_raw(const std::string& path, int width, int height, const ListedAt& listed_at) {
  cv::Mat depth = read_image(path, width, height, listed_at);
  if (depth.type() != CV_16UC1) {
    fail(path, listed_at, "depth image is " + describe(depth) + ", expected 16-bit, 1-channel");
  }
  return depth;
}

DepthToMillimetres::DepthToMillimetres(double scale_correction) : table_(65536) {
  if (!std::isfinite(scale_correction) || scale_correction <= 0.0) {
    throw std::invalid_argument("depth scale correction must be finite and > 0");
  }
  // 5000 units per metre = 5 units per millimetre.
  const double mm_per_unit = scale_correction / 5.0;
  for (size_t raw = 0; raw < table_.size(); ++raw) {
    const double mm = std::round(static_cast<double>(raw) * mm_per_unit);
    table_[raw] = static_cast<uint16_t>(std::min(mm, 65535.0));
  }
}

cv::Mat DepthToMillimetres::operator()(const cv::Mat& depth_raw) const {
  CV_Assert(depth_raw.type() == CV_16UC1);
  cv::Mat mm(depth_raw.size(), CV_16UC1);
  for (int r = 0; r < depth_raw.rows; ++r) {
    const uint16_t* in = depth_raw.ptr<uint16_t>(r);
    uint16_t* out = mm.ptr<uint16_t>(r);
    for (int c = 0; c < depth_raw.cols; ++c) out[c] = table_[in[c]];
  }
  return mm;
}

}  // namespace kestrel::tum
