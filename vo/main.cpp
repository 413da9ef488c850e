// kestrel-vo: visual odometry. As a process (default) it reads CAMERA_RGBD and publishes one
// VO_UPDATE per frame (relative motion, covariance, status and counts), with heartbeats and
// lock-step replay. With --tum DIR it runs in process over a TUM RGB-D folder instead and
// writes the camera trajectory (TUM format, at the RGB time stamps) and optional statistics;
// a run in which no frame gave a motion is bad input (exit 3) and writes nothing.
// See vo/README.md.

#include <spdlog/spdlog.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/time.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/rgbd_frame_t.hpp"
#include "sensors/builtin_profiles.h"
#include "sensors/profile_file.h"
#include "vo/option_keys.h"
#include "vo/sensor_profile.h"
#include "vo/sequence_run.h"
#include "vo/update_message.h"
#include "vo/variants.h"

namespace {

using namespace kestrel;

struct Options {
  std::string variant = "default";
  std::vector<std::string> settings;  // KEY=VALUE over the variant
  std::string sensor;                 // a sensor profile's name or file; empty: the TUM folder's, else the frames'
  // Offline.
  std::string tum;
  std::string out;
  std::string stats;
  // Process.
  std::string name = "vo";
  std::string lcm_url;
  std::string in_channel = channel::kCameraRgbd;
  std::string out_channel = channel::kVoUpdate;
};

// The pipeline's options for camera profile `sensor`: the variant's, then the profile's, then
// each --set (which may change what the profile set).
vo::VoOptions configured(const Options& o, const sensors::SensorProfile& sensor) {
  vo::VoOptions options;
  try {
    options = vo::variant(o.variant).options;
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--variant", e.what());
  }
  try {
    options = vo::with_sensor(sensor, options);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--sensor", "profile '" + sensor.name + "': " + e.what());
  }
  for (const std::string& kv : o.settings) {
    try {
      vo::set_option_assignment(options, kv);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--set", e.what());
    }
  }
  return options;
}

// Nothing is written for a run that estimated nothing: a trajectory holding only the first
// frame's identity pose, and figures of zeros, would read as a perfect result.
int run_offline(const Options& o, const vo::VoOptions& options) {
  if (o.out.empty()) throw CLI::RequiredError("--out (with --tum)");
  const vo::LoadedSequence sequence = vo::load_tum_sequence(o.tum);
  const vo::SequenceRun run = vo::run_sequence(sequence.frames, options);
  const vo::RunFigures f = vo::score(run, sequence.ground_truth);
  vo::require_usable(run.results, o.tum);  // InputError: exit 3
  write_tum_trajectory(o.out, run.trajectory);
  const size_t unpaired = sequence.rgb_images - f.frames;
  std::cout << "frames: " << f.frames << " of " << sequence.rgb_images << " RGB images (" << unpaired
            << " without a depth image within " << format_seconds(sequence.max_time_difference_us) << " s)\n"
            << "with a motion: " << f.ok << " (" << 100.0 * double(f.ok) / double(f.frames)
            << " %); by status: " << vo::status_summary(f) << "\n"
            << "ms per frame: median " << f.median_ms << ", p95 " << f.p95_ms << "\n";
  // The first frame is the reference; any other frame without a motion is a gap in the output.
  if (f.ok + 1 < f.frames)
    spdlog::warn("{}: {} of {} frames gave no motion ({})", o.tum, f.frames - f.ok, f.frames, vo::status_summary(f));
  if (unpaired > 0) spdlog::warn("{}: {} RGB images have no depth image and were skipped", o.tum, unpaired);
  if (!sequence.ground_truth.empty() && !f.scored) {
    std::cout << "accuracy: not measured (" << f.not_scored << ")\n";
  } else if (f.scored) {
    std::cout << "ATE RMSE: " << f.ate_rmse_m << " m (" << f.scored_frames << " frames with ground truth)\n"
              << "RPE (1 s): " << f.rpe_translation_mps << " m/s, " << f.rpe_rotation_degps << " deg/s\n"
              << "mean velocity error: " << f.velocity_error_mps << " m/s\n"
              << "gross failures: " << f.gross << " (" << f.gross_percent << " %)\n"
              << "NEES: mean " << f.mean_nees << " (6 if consistent), " << 100.0 * f.nees_within_95
              << " % under the 95 % bound, " << f.nees_frames << " frames\n";
  }
  if (!o.stats.empty()) {
    kestrel::write_file_atomically(o.stats, vo::stats_json(run, f, o.variant) + "\n");
  }
  return kExitOk;
}

// The process's odometry runs with the camera's profile: --sensor's, else the one the frames'
// sensor model names (a log keeps it, so a replay runs as the live camera did). It is made at
// the first frame and made again when the model changes (another source: the motion cannot be
// chained across it, so the odometry restarts, as after a lost frame).
int serve(const Options& o, const std::optional<sensors::SensorProfile>& forced) {
  if (!o.out.empty() || !o.stats.empty()) throw CLI::ValidationError("--out/--stats", "only with --tum");
  std::optional<sensors::SensorProfile> profile;
  std::unique_ptr<vo::VisualOdometry> odometry;
  auto odometry_for = [&](const RgbdFrame& frame) -> vo::VisualOdometry& {
    const sensors::SensorProfile& wanted = forced ? *forced : sensors::profile_of_sensor(frame.sensor);
    if (odometry && wanted.name == profile->name) return *odometry;
    const std::string why = forced ? "--sensor" : "the frames' sensor '" + frame.sensor + "'";
    if (odometry) {
      spdlog::warn("{}: frame {}: the camera is now {} ({}): the odometry restarts", o.in_channel, frame.utime,
                   wanted.name, why);
    } else {
      spdlog::info("camera profile: {} ({})", wanted.name, why);
    }
    odometry = std::make_unique<vo::VisualOdometry>(configured(o, wanted));
    profile = wanted;
    return *odometry;
  };
  std::unique_ptr<transport::Node> node;
  node = std::make_unique<transport::Node>(o.name, o.lcm_url);  // UnavailableError: exit 4
  node->advertise(o.out_channel);
  node->on_reset([&] {
    if (odometry) odometry->reset();
  });
  int64_t frames = 0, ok = 0;
  node->subscribe<rgbd_frame_t>(o.in_channel, [&](const rgbd_frame_t& message) {
    RgbdFrame frame;
    try {
      frame = transport::decode_rgbd(message, o.in_channel.c_str());
    } catch (const InputError&) {
      // Consumers learn that a frame was lost; the Node counts and logs the reason.
      node->publish(o.out_channel, vo::bad_input_message(message.utime, message.seq));
      throw;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const vo::VoResult r = odometry_for(frame).process(frame);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    node->publish(o.out_channel, vo::to_message(r, frame.T_body_camera, ms));
    ++frames;
    ok += r.status == vo::VoStatus::kOk;
    if (r.status != vo::VoStatus::kOk && r.status != vo::VoStatus::kNoReference)
      spdlog::debug("{}: frame {}: {}", o.in_channel, r.utime, r.message);
  });
  node->set_health(process_status_t::STATE_RUNNING, "");
  spdlog::info("{}: {} -> {} (variant {})", o.name, o.in_channel, o.out_channel, o.variant);
  const int status = node->spin();
  spdlog::info("{} frames, {} with a motion, {} rejected", frames, ok, node->counters().messages_rejected);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("vo",
               "Visual odometry (fovis pipeline): CAMERA_RGBD -> VO_UPDATE, or with --tum an "
               "offline run over a TUM RGB-D folder that writes the trajectory.");
  Options o;
  std::string known;
  for (const auto& v : vo::variants()) known += (known.empty() ? "" : ", ") + v.name;
  app.add_option("--variant", o.variant, "Pipeline variant (paper's Table 1): " + known)
      ->capture_default_str();
  app.add_option("--set", o.settings,
                 "Change one option of the variant, KEY=VALUE (repeatable; --list-options shows them)");
  bool list = false;
  app.add_option("--sensor", o.sensor,
                 "Camera profile: a built-in one (simulator: global shutter, keyframe floors capped; kinect1: "
                 "rolling shutter, depth before colour, larger covariance floors; default: nothing changed) or a "
                 "profile file of your own (sensors/README.md); by default the one each frame's sensor model "
                 "names, or default (with --tum the folder's: kinect1 for freiburg1)")
      ->check(CLI::Validator([](std::string& name) { return sensors::check_sensor_profile_name(name); }, "PROFILE"));
  app.add_flag("--list-options", list, "Print every pipeline option of the variant with its value and exit");
  app.add_option("--tum", o.tum, "Offline: TUM RGB-D sequence folder to run over");
  app.add_option("--out", o.out, "Offline: write the camera trajectory here (TUM format)");
  app.add_option("--stats", o.stats, "Offline: write figures and per-frame status here (JSON)");
  app.add_option("--name", o.name, "Process name in heartbeats")->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--in", o.in_channel, "Channel of rgbd_frame_t")->capture_default_str();
  app.add_option("--out-channel", o.out_channel, "Channel of vo_update_t")->capture_default_str();
  return app.run(argc, argv, [&]() -> int {
    // The camera's profile: as told, else the TUM folder's; live, else each frame's (serve()).
    std::optional<sensors::SensorProfile> forced;
    if (!o.sensor.empty()) {
      forced = sensors::load_sensor_profile(o.sensor);  // a bad file: InputError, exit 3
    } else if (!o.tum.empty()) {
      forced = vo::tum_sensor(o.tum);
    }
    // Every profile the run may take is checked now, so a bad --set is a usage error at the start.
    if (forced) {
      configured(o, *forced);
    } else {
      for (const sensors::SensorProfile& p : sensors::builtin_profiles()) configured(o, p);
    }
    // Live without --sensor, each frame's profile applies (serve()); --list-options shows the
    // options before any camera's: the built-in defaults.
    const vo::VoOptions options = configured(o, forced ? *forced : sensors::builtin_profile("default"));
    if (list) {
      for (const std::string& line : vo::describe_options(options)) std::cout << line << "\n";
      return kExitOk;
    }
    if (!o.tum.empty()) {
      spdlog::info("camera profile: {}", forced->name);
      return run_offline(o, options);
    }
    return serve(o, forced);
  });
}
