#pragma once
// RGB-D frames between their in-memory form (common/rgbd_frame.h) and rgbd_frame_t.
//
// Raw encodings are for onboard links; JPEG colour and zstd depth (lossless) cut a 640x480
// frame from 1.5 MB to about 100 kB for the link to the ground station.
//
// Invariants: decoding is a pure function of the message. A failed decode keeps no state (a
// decoder handle whose call failed is discarded), so the frames after a corrupt one decode
// exactly as they would alone; bad input, including a camera no pinhole camera can be
// (rgbd_codec.cpp, check_plausible_camera), only ever throws InputError.

#include <functional>

#include "common/rgbd_frame.h"
#include "kestrel/rgbd_frame_t.hpp"

namespace kestrel::transport {

struct RgbdEncoding {
  int8_t rgb = kestrel::rgbd_frame_t::RGB_RGB8;
  int8_t depth = kestrel::rgbd_frame_t::DEPTH_U16_MM;
  int jpeg_quality = 90;  ///< 1..100, for RGB_JPEG
  int zstd_level = 1;     ///< for DEPTH_U16_MM_ZSTD; 1 is fast and already ~4x on Kinect depth
};

/// Encodes `frame` (which must satisfy RgbdFrame's invariants).
kestrel::rgbd_frame_t encode_rgbd(const RgbdFrame& frame, const RgbdEncoding& encoding = {});

/// Decodes a message; throws InputError naming `what` (usually the channel) if the encoding
/// is unknown, the data is corrupt, truncated or of another size than the camera, or the
/// camera or its mounting is invalid or implausible.
RgbdFrame decode_rgbd(const kestrel::rgbd_frame_t& message, const char* what);

/// A frame decoded but for its JPEG colour, and what decodes that colour when it is wanted.
struct RgbdDeferredColour {
  RgbdFrame frame;                  ///< `rgb` empty when `colour` is set
  std::function<cv::Mat()> colour;  ///< set for JPEG colour only: the image, or InputError as decode_rgbd
};
/// decode_rgbd, but JPEG colour is only checked (its header and size) and decoded when
/// `colour` is called, any number of times and after the message is gone. For a consumer
/// that keeps the colour of few frames (the mapper's keyframes): decoding every frame's JPEG
/// as it arrived was most of the mapper's CPU time. Raw colour is copied as by decode_rgbd. A
/// frame whose only image is deferred colour comes back with no image (RgbdFrame::validate
/// refuses it); the caller decides whether it needs the depth.
RgbdDeferredColour decode_rgbd_deferring_colour(const kestrel::rgbd_frame_t& message, const char* what);

}  // namespace kestrel::transport
