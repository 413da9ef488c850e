#include "common/rgbd_frame.h"

#include <cmath>
#include <limits>

#include "common/error.h"

namespace kestrel {

void RgbdFrame::validate(const char* what) const {
  camera.validate(what);
  auto fail = [&](const std::string& why) { throw InputError(std::string(what) + ": " + why); };
  if (rgb.empty() && depth_mm.empty()) fail("frame has neither colour nor depth");
  if (!rgb.empty()) {
    if (rgb.type() != CV_8UC3) fail("colour image is not 8-bit, 3-channel");
    if (rgb.cols != camera.width || rgb.rows != camera.height)
      fail("colour image is " + std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) +
           " but the camera is " + std::to_string(camera.width) + "x" +
           std::to_string(camera.height));
  }
  if (!depth_mm.empty()) {
    if (depth_mm.type() != CV_16UC1) fail("depth image is not 16-bit, 1-channel");
    if (depth_mm.cols != camera.width || depth_mm.rows != camera.height)
      fail("depth image is " + std::to_string(depth_mm.cols) + "x" +
           std::to_string(depth_mm.rows) + " but the camera is " + std::to_string(camera.width) +
           "x" + std::to_string(camera.height));
  }
}

cv::Mat depth_to_metres(const cv::Mat& depth_mm) {
  CV_Assert(depth_mm.type() == CV_16UC1);
  cv::Mat out(depth_mm.size(), CV_32FC1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int r = 0; r < depth_mm.rows; ++r) {
    const uint16_t* in = depth_mm.ptr<uint16_t>(r);
    float* o = out.ptr<float>(r);
    for (int c = 0; c < depth_mm.cols; ++c) o[c] = in[c] == 0 ? nan : 0.001f * in[c];
  }
  return out;
}

cv::Mat depth_to_millimetres(const cv::Mat& depth_m) {
  CV_Assert(depth_m.type() == CV_32FC1);
  cv::Mat out(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* in = depth_m.ptr<float>(r);
    uint16_t* o = out.ptr<uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const float mm = in[c] * 1000.0f;
      // The negated comparison also sends NaN to 0.
      o[c] = !(mm >= 0.5f && mm < 65535.5f) ? 0 : static_cast<uint16_t>(std::lround(mm));
    }
  }
  return out;
}

}  // namespace kestrel
