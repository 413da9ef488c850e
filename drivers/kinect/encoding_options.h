#pragma once
// Command-line options that choose how a source encodes its RGB-D frames on the wire
// (transport::RgbdEncoding), shared by kestrel-kinect and kestrel-tum-play.
//
//   --rgb-encoding raw|jpeg    raw = RGB8 (exact), jpeg = lossy, ~15x smaller
//   --depth-encoding raw|zstd  both exact; zstd ~4x smaller on Kinect depth
//   --jpeg-quality 1..100, --zstd-level 1..19

#include <CLI/CLI.hpp>
#include <string>

#include "common/transport/rgbd_codec.h"

namespace kestrel::kinect {

struct EncodingOptions {
  std::string rgb = "raw";
  std::string depth = "raw";
  int jpeg_quality = 90;
  int zstd_level = 1;

  void add_to(CLI::App& app) {
    app.add_option("--rgb-encoding", rgb, "Colour on the wire: raw (RGB8) or jpeg")
        ->check(CLI::IsMember({"raw", "jpeg"}))
        ->capture_default_str();
    app.add_option("--depth-encoding", depth, "Depth on the wire: raw (uint16 mm) or zstd")
        ->check(CLI::IsMember({"raw", "zstd"}))
        ->capture_default_str();
    app.add_option("--jpeg-quality", jpeg_quality, "JPEG quality for --rgb-encoding jpeg")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    app.add_option("--zstd-level", zstd_level, "zstd level for --depth-encoding zstd")
        ->check(CLI::Range(1, 19))
        ->capture_default_str();
  }

  transport::RgbdEncoding encoding() const {
    transport::RgbdEncoding e;
    e.rgb = rgb == "jpeg" ? kestrel::rgbd_frame_t::RGB_JPEG : kestrel::rgbd_frame_t::RGB_RGB8;
    e.depth = depth == "zstd" ? kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD
                              : kestrel::rgbd_frame_t::DEPTH_U16_MM;
    e.jpeg_quality = jpeg_quality;
    e.zstd_level = zstd_level;
    return e;
  }
};

}  // namespace kestrel::kinect
