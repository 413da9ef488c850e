// kestrel-rgbd-codec: republishes every RGB-D frame of one channel on another with a
// different encoding, e.g. JPEG + zstd for the radio link to the ground station, or raw
// again on the far side. A Node process: heartbeats, lock-step replay, bad frames counted
// and skipped.

#include <spdlog/spdlog.h>

#include <stdexcept>
#include <string>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/rgbd_frame_t.hpp"
#include "tools/codec/transcoder.h"

namespace {

using kestrel::rgbd_frame_t;

struct Options {
  std::string name = "rgbd-codec";
  std::string lcm_url;
  std::string in_channel = kestrel::channel::kCameraRgbd;
  std::string out_channel = "CAMERA_RGBD_Z";
  std::string rgb = "jpeg";
  std::string depth = "zstd";
  int jpeg_quality = 90;
  int zstd_level = 1;
  double max_rate_hz = 0;
};

int serve(const Options& o) {
  if (o.in_channel == o.out_channel)
    throw CLI::ValidationError("--out", "must differ from --in (the codec would feed itself)");
  kestrel::transport::RgbdEncoding encoding;
  encoding.rgb = o.rgb == "jpeg" ? rgbd_frame_t::RGB_JPEG : rgbd_frame_t::RGB_RGB8;
  encoding.depth = o.depth == "zstd" ? rgbd_frame_t::DEPTH_U16_MM_ZSTD : rgbd_frame_t::DEPTH_U16_MM;
  encoding.jpeg_quality = o.jpeg_quality;
  encoding.zstd_level = o.zstd_level;
  kestrel::codec::RgbdTranscoder transcoder(encoding);
  kestrel::codec::FrameRateLimit limit(o.max_rate_hz);
  int64_t thinned = 0;
  std::unique_ptr<kestrel::transport::Node> node;
  node = std::make_unique<kestrel::transport::Node>(o.name, o.lcm_url);  // UnavailableError: exit 4
  node->advertise(o.out_channel);
  node->on_reset([&] {
    transcoder.reset();
    limit.reset();
  });
  node->subscribe<rgbd_frame_t>(o.in_channel, [&](const rgbd_frame_t& frame) {
    if (!limit.keep(frame.utime)) {
      ++thinned;
      return;
    }
    node->publish(o.out_channel, transcoder.transcode(frame, o.in_channel.c_str()));
  });
  spdlog::info("{}: {} -> {}", o.name, o.in_channel, o.out_channel);
  const int status = node->spin();
  const auto& s = transcoder.stats();
  spdlog::info("{} frames, {:.1f} MB in, {:.1f} MB out, {} rejected, {} left out by --max-rate", s.frames,
               s.bytes_in * 1e-6, s.bytes_out * 1e-6, node->counters().messages_rejected, thinned);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("rgbd-codec",
                        "Republishes each RGB-D frame of one channel on another, in another "
                        "encoding (JPEG/raw colour, zstd/raw depth; depth stays lossless).");
  Options o;
  app.add_option("--name", o.name, "Process name in heartbeats (unique within a launch)")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--in", o.in_channel, "Channel to read rgbd_frame_t from")->capture_default_str();
  app.add_option("--out", o.out_channel, "Channel to publish on")->capture_default_str();
  app.add_option("--rgb", o.rgb, "Colour encoding out: jpeg or raw")
      ->check(CLI::IsMember({"jpeg", "raw"}))
      ->capture_default_str();
  app.add_option("--depth", o.depth, "Depth encoding out: zstd or raw (both lossless)")
      ->check(CLI::IsMember({"zstd", "raw"}))
      ->capture_default_str();
  app.add_option("--jpeg-quality", o.jpeg_quality, "JPEG quality")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--zstd-level", o.zstd_level, "zstd level (1 fast .. 19 small)")
      ->check(CLI::Range(1, 19))
      ->capture_default_str();
  app.add_option("--max-rate", o.max_rate_hz,
                 "Publish at most this many frames per second of sensor time (0: every frame)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return app.run(argc, argv, [&] { return serve(o); });
}
