#include "tools/codec/transcoder.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/error.h"

namespace kestrel::codec {

using kestrel::rgbd_frame_t;

RgbdTranscoder::RgbdTranscoder(const transport::RgbdEncoding& target) : target_(target) {
  if (target.rgb != rgbd_frame_t::RGB_RGB8 && target.rgb != rgbd_frame_t::RGB_JPEG)
    throw std::invalid_argument("colour target must be raw RGB8 or JPEG");
  if (target.depth != rgbd_frame_t::DEPTH_U16_MM && target.depth != rgbd_frame_t::DEPTH_U16_MM_ZSTD)
    throw std::invalid_argument("depth target must be raw or zstd");
  if (target.jpeg_quality < 1 || target.jpeg_quality > 100)
    throw std::invalid_argument("JPEG quality must be within 1..100, got " +
                                std::to_string(target.jpeg_quality));
  // zstd's "ultra" levels above 19 need far more memory than a frame is worth.
  if (target.zstd_level < 1 || target.zstd_level > 19)
    throw std::invalid_argument("zstd level must be within 1..19, got " +
                                std::to_string(target.zstd_level));
}

rgbd_frame_t RgbdTranscoder::transcode(const rgbd_frame_t& in, const char* what) {
  // Decoding everything validates the message even for the parts that pass through.
  RgbdFrame frame = transport::decode_rgbd(in, what);
  const bool keep_rgb = in.rgb_encoding == rgbd_frame_t::RGB_NONE || in.rgb_encoding == target_.rgb;
  const bool keep_depth =
      in.depth_encoding == rgbd_frame_t::DEPTH_NONE || in.depth_encoding == target_.depth;

  rgbd_frame_t out;
  if (keep_rgb && keep_depth) {
    out = in;
  } else {
    if (keep_rgb) frame.rgb.release();
    if (keep_depth) frame.depth_mm.release();
    out = transport::encode_rgbd(frame, target_);
    // The camera pose would come back through a quaternion round trip; keep the sender's
    // exact bytes instead.
    out.camera = in.camera;
    if (keep_rgb) {
      out.rgb_encoding = in.rgb_encoding;
      out.rgb = in.rgb;
      out.rgb_size = in.rgb_size;
    }
    if (keep_depth) {
      out.depth_encoding = in.depth_encoding;
      out.depth = in.depth;
      out.depth_size = in.depth_size;
    }
  }
  ++stats_.frames;
  stats_.bytes_in += in.getEncodedSize();
  stats_.bytes_out += out.getEncodedSize();
  return out;
}

FrameRateLimit::FrameRateLimit(double max_rate_hz) {
  if (!std::isfinite(max_rate_hz) || max_rate_hz < 0)
    throw std::invalid_argument("the frame rate limit must be finite and >= 0");
  if (max_rate_hz > 0) min_gap_us_ = std::llround(0.9e6 / max_rate_hz);
}

bool FrameRateLimit::keep(int64_t utime) {
  if (last_kept_ >= 0 && utime >= last_kept_ && utime - last_kept_ < min_gap_us_) return false;
  last_kept_ = utime;
  return true;
}

}  // namespace kestrel::codec
