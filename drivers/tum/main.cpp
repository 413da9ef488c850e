// kestrel-tum-play: publishes a TUM RGB-D sequence as kestrel messages (CAMERA_RGBD, IMU,
// GROUND_TRUTH), paced in real time or at a rate factor, or writes them straight to an LCM
// log (--log) as fast as possible without touching the network. See README.md.

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

#include "common/cli.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/node.h"
#include "drivers/kinect/encoding_options.h"
#include "drivers/tum/playback.h"
#include "drivers/tum/player.h"
#include "drivers/tum/tum_sequence.h"

namespace {

using namespace kestrel;

struct Options {
  std::string folder;
  std::string log;
  std::string lcm_url;
  double rate = 1.0;
  bool loop = false;
  double start_s = 0.0;
  double duration_s = 0.0;
  double max_dt_s = 0.02;
  double depth_scale = 1.0;
  std::vector<double> intrinsics;
  bool no_imu = false;
  bool no_ground_truth = false;
  bool raw_accel_axes = false;
  kinect::EncodingOptions encoding;
};

void add_options(cli::App& app, Options& o) {
  app.add_option("folder", o.folder, "TUM RGB-D sequence folder (rgb.txt, depth.txt, ...)")->required();
  app.add_option("--log", o.log, "Write an LCM log here instead of publishing (no network, full speed)");
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--rate", o.rate, "Playback speed, sensor seconds per wall second")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_flag("--loop", o.loop, "Start again after the end (time stamps keep increasing)");
  app.add_option("--start", o.start_s, "Skip this many seconds after the first frame")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "Play this many seconds (0 = to the end)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--max-dt", o.max_dt_s, "Largest RGB-depth time difference of a frame, seconds")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--depth-scale", o.depth_scale, "Depth scale correction (fr1: about 1.035)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--intrinsics", o.intrinsics,
                 "fx,fy,cx,cy instead of TUM's values for the camera named in the folder")
      ->expected(4)
      ->delimiter(',');
  app.add_flag("--no-imu", o.no_imu, "Do not publish the accelerometer");
  app.add_flag("--no-ground-truth", o.no_ground_truth, "Do not publish the ground truth");
  app.add_flag("--raw-accel-axes", o.raw_accel_axes,
               "IMU on the Kinect accelerometer's own axes instead of the body (camera) frame");
  o.encoding.add_to(app);
}

tum::TumSequence open_sequence(const Options& o) {
  tum::SequenceOptions so;
  so.max_time_difference_us = std::llround(o.max_dt_s * 1e6);
  so.depth_scale_correction = o.depth_scale;
  so.intrinsics = cli::intrinsics_option(o.intrinsics);
  return tum::TumSequence(o.folder, so);
}

int run(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const tum::TumSequence sequence = open_sequence(o);
  const auto& a = sequence.association();
  spdlog::info("{}: {} frames ({} camera, fx={}), {} unmatched RGB images, {} unused depth images, {} shared",
               o.folder, a.frames,
               sequence.has_camera_file() ? "camera.txt's" : tum::camera_name(sequence.camera_model()),
               sequence.camera().fx,
               a.unmatched_rgb, a.unused_depth, a.shared_depth);
  if (!sequence.has_ground_truth() && !o.no_ground_truth)
    spdlog::warn("{}: no groundtruth.txt, publishing no ground truth", o.folder);
  if (!sequence.has_accelerometer() && !o.no_imu)
    spdlog::warn("{}: no accelerometer.txt, publishing no IMU", o.folder);

  tum::PlaybackWindow window;
  window.start_s = o.start_s;
  window.duration_s = o.duration_s;
  window.imu = !o.no_imu;
  window.ground_truth = !o.no_ground_truth;
  const auto events = tum::playback_schedule(sequence, window);
  if (events.empty()) throw CLI::ValidationError("--start/--duration", "no frame of the sequence lies in that window");

  tum::PlayerOptions po;
  po.loop = o.loop;
  po.raw_accel_axes = o.raw_accel_axes;
  po.encoding = o.encoding.encoding();
  tum::PlayerStats stats;
  if (!o.log.empty()) {
    if (o.loop) throw CLI::ValidationError("--loop", "cannot loop into a log file (--log)");
    catch_interrupts();
    transport::LogWriter log(o.log);
    po.rate = 0.0;
    tum::PlayerSink sink;
    sink.publish = [&](const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
      log.write(channel, utime, bytes);
    };
    sink.stopping = [] { return interrupted(); };
    stats = tum::play(sequence, events, po, sink);
    log.close();
  } else {
    std::optional<transport::Node> node;
    node.emplace("tum-play", o.lcm_url);  // UnavailableError: exit 4
    for (const char* c : {channel::kCameraRgbd, channel::kImu, channel::kGroundTruth}) node->advertise(c);
    node->set_health(kestrel::process_status_t::STATE_RUNNING, "");
    po.rate = o.rate;
    tum::PlayerSink sink;
    sink.publish = [&](const std::string& channel, int64_t, const std::vector<uint8_t>& bytes) {
      node->publish_bytes(channel, bytes);
      node->spin_once(0);
    };
    sink.stopping = [&] { return node->stopping(); };
    sink.idle = [&] { node->spin_once(0); };
    stats = tum::play(sequence, events, po, sink);
  }

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "frames published: " << stats.frames << "\n"
            << "unmatched RGB frames: " << a.unmatched_rgb << "\n"
            << "unused depth frames: " << a.unused_depth << "\n"
            << "depth frames serving two RGB frames: " << a.shared_depth << "\n"
            << "IMU samples published: " << stats.imu_samples << "\n"
            << "ground-truth poses published: " << stats.ground_truth_poses << "\n"
            << "time taken: " << seconds << " s\n";
  if (o.log.empty() && o.rate > 0.0) spdlog::info("largest delay behind schedule: {:.1f} ms", stats.max_lateness_s * 1e3);
  return stats.stopped ? kExitInterrupted : kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("tum-play", "Publish a TUM RGB-D sequence (CAMERA_RGBD, IMU, GROUND_TRUTH) or write it to an LCM log");
  Options options;
  add_options(app, options);
  return app.run(argc, argv, [&] { return run(options); });
}
