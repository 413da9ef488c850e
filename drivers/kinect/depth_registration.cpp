#include "drivers/kinect/depth_registration.h"

#include <algorithm>

#include "common/rgbd_frame.h"

namespace kestrel::kinect {
namespace {

const KinectCalibration& validated(const KinectCalibration& c) {
  c.validate();
  return c;
}

}  // namespace

DepthRegistration::DepthRegistration(const KinectCalibration& calibration)
    : calibration_(validated(calibration)),
      metres_of_raw_(calibration.disparity.table()),
      ir_to_rgb_(calibration.ir, calibration.rgb, calibration.T_rgb_ir()),
      rgb_to_ir_(calibration.rgb, calibration.ir, calibration.T_ir_rgb) {}

cv::Mat DepthRegistration::register_raw(const cv::Mat& raw_ir) const {
  CV_Assert(raw_ir.type() == CV_16UC1 && raw_ir.cols == calibration_.ir.width &&
            raw_ir.rows == calibration_.ir.height);
  cv::Mat metres(raw_ir.size(), CV_32FC1);
  for (int v = 0; v < raw_ir.rows; ++v) {
    const uint16_t* in = raw_ir.ptr<uint16_t>(v);
    float* out = metres.ptr<float>(v);
    // The device never sends more than 11 bits; a corrupt value must not index past the table.
    for (int u = 0; u < raw_ir.cols; ++u) out[u] = metres_of_raw_[std::min<uint16_t>(in[u], 2047)];
  }
  return depth_to_millimetres(ir_to_rgb_(metres));
}

cv::Mat DepthRegistration::unregister_mm(const cv::Mat& depth_rgb_mm) const {
  CV_Assert(depth_rgb_mm.type() == CV_16UC1 && depth_rgb_mm.cols == calibration_.rgb.width &&
            depth_rgb_mm.rows == calibration_.rgb.height);
  cv::Mat metres(depth_rgb_mm.size(), CV_32FC1);
  for (int v = 0; v < depth_rgb_mm.rows; ++v) {
    const uint16_t* in = depth_rgb_mm.ptr<uint16_t>(v);
    float* out = metres.ptr<float>(v);
    for (int u = 0; u < depth_rgb_mm.cols; ++u) out[u] = 0.001f * static_cast<float>(in[u]);
  }
  const cv::Mat ir_metres = rgb_to_ir_(metres);
  cv::Mat raw(ir_metres.size(), CV_16UC1);
  const DisparityModel& model = calibration_.disparity;
  for (int v = 0; v < raw.rows; ++v) {
    const float* in = ir_metres.ptr<float>(v);
    uint16_t* out = raw.ptr<uint16_t>(v);
    for (int u = 0; u < raw.cols; ++u) out[u] = model.raw(static_cast<double>(in[u]));
  }
  return raw;
}

}  // namespace kestrel::kinect
