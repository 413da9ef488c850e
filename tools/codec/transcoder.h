#pragma once
// Re-encodes RGB-D frame messages (rgbd_frame_t) to a target encoding: JPEG or raw colour,
// zstd or raw depth. This is the whole job of kestrel-rgbd-codec, kept free of LCM so that
// tests and benchmarks call it directly.
//
// Invariants of transcode():
//  * every input is fully decoded first, so a corrupt, truncated or inconsistent frame is
//    rejected (InputError naming the channel) and never forwarded;
//  * a component already in its target encoding is copied byte for byte, never re-encoded
//    (re-compressing a JPEG would lose quality at every hop), and so is the whole message
//    when both components already are;
//  * time stamps, sequence number and camera description are copied unchanged, so the
//    output differs from the input only in its image encodings;
//  * depth is always lossless (zstd or raw); colour is lossy only when JPEG is asked for.

#include <cstdint>

#include "common/transport/rgbd_codec.h"
#include "kestrel/rgbd_frame_t.hpp"

namespace kestrel::codec {

struct TranscoderStats {
  int64_t frames = 0;       ///< frames transcoded (rejected ones are not counted)
  int64_t bytes_in = 0;     ///< encoded message sizes in
  int64_t bytes_out = 0;    ///< encoded message sizes out
};

class RgbdTranscoder {
 public:
  /// `target.rgb` is RGB_RGB8 or RGB_JPEG, `target.depth` DEPTH_U16_MM or DEPTH_U16_MM_ZSTD;
  /// throws std::invalid_argument otherwise, or for a JPEG quality outside 1..100 or a zstd
  /// level outside 1..19.
  explicit RgbdTranscoder(const transport::RgbdEncoding& target);

  /// `in` in the target encoding. Throws InputError naming `what` if `in` is not a valid
  /// frame.
  kestrel::rgbd_frame_t transcode(const kestrel::rgbd_frame_t& in, const char* what);

  const TranscoderStats& stats() const { return stats_; }
  /// Forgets the statistics (the transcoder has no other state).
  void reset() { stats_ = {}; }

 private:
  transport::RgbdEncoding target_;
  TranscoderStats stats_;
};

/// Thins a stream of frames to at most `max_rate_hz` by their sensor time (utime): a frame is
/// kept if it is the first, or at least 0.9 of a period after the last one kept, so a 30 Hz
/// camera thinned to 10 Hz keeps every third frame despite jitter in the stamps. A frame
/// stamped before the last one kept (a restarted source) is kept and starts again from it.
/// `max_rate_hz` 0 keeps every frame. For the radio link: SLAM and the mapper need only
/// the frames that become keyframes, and lossless depth at 30 Hz does not fit 20 Mbit/s.
class FrameRateLimit {
 public:
  explicit FrameRateLimit(double max_rate_hz);  ///< throws std::invalid_argument if < 0 or not finite
  bool keep(int64_t utime);
  void reset() { last_kept_ = -1; }

 private:
  int64_t min_gap_us_ = 0;
  int64_t last_kept_ = -1;
};

}  // namespace kestrel::codec
