#include "station/images.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/rgbd_frame.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::station {
namespace {

// The codec's JPEG encoder, reached through a frame that holds only `rgb`.
std::vector<uint8_t> jpeg_of(const RgbdFrame& like, const cv::Mat& rgb, int quality) {
  RgbdFrame f;
  f.utime = like.utime;
  f.depth_utime = like.depth_utime;
  f.camera = like.camera;
  f.T_body_camera = like.T_body_camera;
  f.rgb = rgb;
  transport::RgbdEncoding e;
  e.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  e.jpeg_quality = quality;
  return transport::encode_rgbd(f, e).rgb;
}

}  // namespace

cv::Mat depth_picture(const cv::Mat& depth_mm, double far_m) {
  cv::Mat out(depth_mm.rows, depth_mm.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  const double far_mm = std::max(far_m, 0.1) * 1000.0;
  for (int r = 0; r < depth_mm.rows; ++r) {
    const auto* d = depth_mm.ptr<uint16_t>(r);
    auto* o = out.ptr<cv::Vec3b>(r);
    for (int c = 0; c < depth_mm.cols; ++c) {
      if (d[c] == 0) continue;
      // Red (near) through green to blue (far): a hue ramp the eye reads as distance.
      const double t = std::min(static_cast<double>(d[c]) / far_mm, 1.0);
      const double red = std::clamp(1.0 - 2.0 * t, 0.0, 1.0);
      const double green = 1.0 - std::abs(2.0 * t - 1.0);
      const double blue = std::clamp(2.0 * t - 1.0, 0.0, 1.0);
      o[c] = cv::Vec3b(static_cast<uint8_t>(255 * red), static_cast<uint8_t>(255 * green), static_cast<uint8_t>(255 * blue));
    }
  }
  return out;
}

PreviewThinner::PreviewThinner(const PreviewOptions& options) : options_(options) {
  if (!(options.period_s > 0.0) || !std::isfinite(options.period_s))
    throw std::invalid_argument("preview period must be > 0 s");
  if (options.jpeg_quality < 1 || options.jpeg_quality > 100)
    throw std::invalid_argument("preview JPEG quality must be 1..100");
}

std::optional<Preview> PreviewThinner::on_frame(const kestrel::rgbd_frame_t& m, const char* channel) {
  if (last_utime_ && m.utime >= *last_utime_ &&
      static_cast<double>(m.utime - *last_utime_) < options_.period_s * 1e6)
    return std::nullopt;
  const RgbdFrame frame = transport::decode_rgbd(m, channel);  // InputError: nothing changes
  Preview p;
  p.utime = frame.utime;
  if (!frame.rgb.empty()) p.colour_jpeg = jpeg_of(frame, frame.rgb, options_.jpeg_quality);
  if (!frame.depth_mm.empty()) p.depth_jpeg = jpeg_of(frame, depth_picture(frame.depth_mm, options_.depth_far_m), options_.jpeg_quality);
  last_utime_ = m.utime;
  return p;
}

}  // namespace kestrel::station
