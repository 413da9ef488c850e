// kestrel-sim: flies the synthetic world and outputs what a Kinect and an IMU would see,
// with exact ground truth: live on LCM (CAMERA_RGBD, IMU, GROUND_TRUTH), paced in real time,
// at --rate or as fast as possible; or into an LCM log (--log) and/or a TUM RGB-D folder
// (--tum), without touching the network. See README.md.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <iostream>
#include <optional>
#include <regex>
#include <thread>

#include "common/interrupt.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/node.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/sim/contact_watch.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/messages.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/tum_writer.h"
#include "drivers/sim/vehicle.h"
#include "drivers/sim/world_catalog.h"
#include "tools/replay/event_filter.h"
#include "tools/replay/lockstep_driver.h"

namespace {

using namespace kestrel;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string world = "room";
  std::string map;
  std::string flight = "loop";
  double duration_s = 20.0;
  uint64_t seed = 1;
  std::string log;
  std::string tum;
  double rate = 1.0;
  std::string lcm_url;
  bool exact = false;
  int motion_blur = 1;
  double max_mean_grey = sim::RgbOptions{}.max_mean_grey;
  std::string rgb_encoding = "jpeg";
  std::string depth_encoding = "zstd";
  int jpeg_quality = 95;
  std::vector<double> intrinsics;
  double tilt_deg = 10.0;
  double camera_rate_hz = 30.0;
  std::string feedback = "state";
  bool hold_start_pose = false;
  std::vector<double> start;  // x, y, z, yaw of the vehicle; empty: the world's take-off pose
  double lockstep_s = 0.0;
  std::vector<std::string> expect;
  std::string record;
  std::string record_channels = ".*";
  double body_radius_m = 0.25;
  bool list = false;
};

void add_options(cli::App& app, Options& o) {
  // Which world is a question of the command line (exit 2); what a world or map file holds is
  // input, checked as it is read (exit 3).
  app.add_option("--world", o.world, "room, floor, office, stata (needs --map), a .world file or a map .yaml")
      ->check(CLI::Validator([](std::string& what) { return sim::unknown_world_error(what); }, ""))
      ->capture_default_str();
  app.add_option("--map", o.map, "ROS occupancy map (yaml) for --world stata, e.g. ../shared/data/maps/stata_basement.yaml");
  app.add_option("--flight", o.flight,
                 "hover, figure8, aggressive, loop, survey, or vehicle (closed loop: flies VEHICLE_COMMAND)")
      ->capture_default_str();
  app.add_option("--vehicle-feedback", o.feedback,
                 "vehicle: what its position controller uses, the estimator's STATE (the truth until the first "
                 "usable STATE) or the truth")
      ->check(CLI::IsMember({"state", "truth"}))
      ->capture_default_str();
  app.add_flag("--hold-start-pose", o.hold_start_pose,
               "vehicle: hold the start pose in the sim's world until commanded (for an estimator started "
               "there, --init-position); by default it holds where the first usable STATE says it is, in "
               "the STATE's world");
  app.add_option("--start", o.start, "vehicle: where it starts, x,y,z,yaw (m, rad; default: the world's take-off pose)")
      ->expected(4)
      ->delimiter(',');
  app.add_option("--lockstep", o.lockstep_s,
                 "vehicle, live: drive the processes in lock-step (tools/replay/README.md): each IMU sample and "
                 "frame waits until every process it reaches, and all they publish in turn (the follower's "
                 "VEHICLE_COMMAND to this vehicle too), is handled, so a flight is the same on any machine; "
                 "the value is the longest wait without progress, in wall seconds (--rate is then ignored; 0 = off)")
      ->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  app.add_option("--expect", o.expect, "--lockstep: processes that must take part (a,b,c)")->delimiter(',');
  app.add_option("--record", o.record,
                 "--lockstep: write GROUND_TRUTH and every message the processes publish to this LCM log, "
                 "stamped with the sensor time of the event that caused it");
  app.add_option("--record-channels", o.record_channels,
                 "--record: only the processes' channels matching this regex (whole name); GROUND_TRUTH always")
      ->check(CLI::Validator(replay::check_channel_regex, "REGEX"))
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "Seconds of flight to simulate")->check(cli::Positive)->capture_default_str();
  app.add_option("--seed", o.seed, "Sensor noise seed (same seed, same bytes)")->capture_default_str();
  app.add_option("--log", o.log, "Write an LCM log here (no network, full speed)");
  app.add_option("--tum", o.tum, "Write a TUM RGB-D folder here (no network, full speed)");
  app.add_option("--rate", o.rate, "Live: sensor seconds per wall second (0 = as fast as possible)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_flag("--exact", o.exact, "Noiseless sensors: exact IMU, depth only quantised, no colour noise");
  app.add_option("--motion-blur", o.motion_blur, "Renders averaged per colour frame (1 = no motion blur)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  app.add_option("--max-mean-grey", o.max_mean_grey,
                 "Auto-exposure: the exposure is lowered where a frame's mean grey would be above this, as a "
                 "Kinect's own does (0 = a fixed exposure)")
      ->check(CLI::Range(0.0, 255.0))
      ->capture_default_str();
  app.add_option("--rgb-encoding", o.rgb_encoding, "Colour on the wire: raw or jpeg")
      ->check(CLI::IsMember({"raw", "jpeg"}))
      ->capture_default_str();
  app.add_option("--depth-encoding", o.depth_encoding, "Depth on the wire: raw or zstd (lossless)")
      ->check(CLI::IsMember({"raw", "zstd"}))
      ->capture_default_str();
  app.add_option("--jpeg-quality", o.jpeg_quality, "JPEG quality")->check(CLI::Range(1, 100))->capture_default_str();
  app.add_option("--intrinsics", o.intrinsics, "fx,fy,cx,cy of the 640x480 camera (default 525,525,319.5,239.5)")
      ->expected(4)
      ->delimiter(',');
  app.add_option("--camera-tilt", o.tilt_deg, "Camera pitched down from body x, degrees")
      ->check(CLI::Range(-90.0, 90.0))
      ->capture_default_str();
  app.add_option("--camera-rate", o.camera_rate_hz, "Frames per second (the IMU and ground truth stay at 200 Hz)")
      ->check(CLI::Range(0.1, 1000.0))
      ->capture_default_str();
  app.add_option("--body-radius", o.body_radius_m,
                 "Radius of the vehicle's sphere: each time it starts touching the world is reported (m)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_flag("--list", o.list, "List the built-in worlds and the flights, then exit");
}

// Where the events go: files, or LCM with pacing.
struct Sinks {
  std::optional<transport::LogWriter> log;
  std::optional<sim::TumFolderWriter> tum;
  std::optional<transport::Node> node;
  void publish(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
    if (log) log->write(channel, utime, bytes);
    if (node) node->publish_bytes(channel, bytes);
  }
};

int run(const Options& o) {
  if (o.list) {
    for (const auto& w : sim::builtin_world_names()) std::cout << "world " << w << "\n";
    std::cout << "world stata (--map FILE.yaml)\n";
    for (const auto& f : sim::flight_names()) std::cout << "flight " << f << "\n";
    std::cout << "flight vehicle (closed loop)\n";
    return kExitOk;
  }
  if (const std::string problem = sim::world_choice_error(o.world, o.map); !problem.empty())
    throw CLI::ValidationError("--world", problem);
  const auto t0 = Clock::now();
  const sim::World world = sim::load_world(o.world, o.map);
  std::unique_ptr<sim::Flight> flight;
  sim::VehicleFlight* vehicle = nullptr;
  try {
    if (o.flight == "vehicle") {
      Eigen::Vector4d start = world.start();
      if (!o.start.empty()) start = Eigen::Vector4d(o.start[0], o.start[1], o.start[2], o.start[3]);
      if (!start.allFinite()) throw CLI::ValidationError("--start", "x, y, z and yaw must be finite");
      auto v = std::make_unique<sim::VehicleFlight>(start, sim::VehicleOptions{}, o.seed);
      vehicle = v.get();
      flight = std::move(v);
    } else {
      flight = sim::make_flight(o.flight, world);
    }
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--flight", e.what());
  }
  sim::SimulationOptions so;
  so.seed = o.seed;
  so.camera.rgb.motion_blur_samples = o.motion_blur;
  so.camera.rgb.max_mean_grey = o.max_mean_grey;
  so.camera.rate_hz = o.camera_rate_hz;
  so.camera.T_body_camera = sim::CameraOptions::default_T_body_camera(o.tilt_deg);
  if (!o.intrinsics.empty()) {
    PinholeCamera& c = so.camera.camera;
    c.fx = o.intrinsics[0], c.fy = o.intrinsics[1], c.cx = o.intrinsics[2], c.cy = o.intrinsics[3];
    if (!(c.fx > 0 && c.fy > 0 && std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) && std::isfinite(c.cy)))
      throw CLI::ValidationError("--intrinsics", "fx and fy must be > 0 and all values finite");
  }
  if (o.exact) {
    so.camera.rgb.noise = false;
    so.camera.depth.noise = false;
    so.imu.noise = false;
  }
  sim::Simulation simulation(world, *flight, so);
  // The closed-loop vehicle is committed one control period ahead of the next event, plus the
  // IMU's 2 ms difference and half a motion-blurred exposure.
  std::optional<sim::VehicleLoop> loop;
  std::optional<sim::VehicleEstimate> estimate;  // the latest usable STATE
  const double loop_lookahead_s =
      vehicle ? 0.002 + vehicle->options().control_period_s +
                    (o.motion_blur > 1 ? 0.5 * so.camera.rgb.exposure_time_s : 0.0)
              : 0.0;
  if (vehicle) loop.emplace(*vehicle, loop_lookahead_s);
  transport::RgbdEncoding encoding;
  encoding.rgb = o.rgb_encoding == "raw" ? kestrel::rgbd_frame_t::RGB_RGB8 : kestrel::rgbd_frame_t::RGB_JPEG;
  encoding.depth = o.depth_encoding == "raw" ? kestrel::rgbd_frame_t::DEPTH_U16_MM : kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  encoding.jpeg_quality = o.jpeg_quality;
  spdlog::info("world '{}' ({} surfaces), flight '{}', {:.1f} s, seed {}; set up in {:.2f} s", world.name(),
               world.surfaces().size(), flight->name(), o.duration_s, o.seed,
               std::chrono::duration<double>(Clock::now() - t0).count());

  Sinks sinks;
  const bool offline = !o.log.empty() || !o.tum.empty();
  if (o.lockstep_s > 0 && offline) throw CLI::ValidationError("--lockstep", "drives live processes: not with --log or --tum");
  if (o.lockstep_s <= 0 && !(o.record.empty() && o.expect.empty()))
    throw CLI::ValidationError(o.record.empty() ? "--expect" : "--record", "only with --lockstep");
  if (!vehicle && !o.start.empty()) throw CLI::ValidationError("--start", "only with --flight vehicle");
  if (!o.log.empty()) sinks.log.emplace(o.log);
  if (!o.tum.empty()) sinks.tum.emplace(o.tum, so.camera.camera, so.camera.T_body_camera);
  bool restart = false;
  if (offline) {
    catch_interrupts();
  } else {
    sinks.node.emplace("sim", o.lcm_url);  // UnavailableError: exit 4
    for (const char* c : {channel::kCameraRgbd, channel::kImu, channel::kGroundTruth}) sinks.node->advertise(c);
    if (vehicle) {
      sinks.node->subscribe<kestrel::vehicle_command_t>(
          channel::kVehicleCommand, [&](const kestrel::vehicle_command_t& m) { loop->set_command(sim::vehicle_command(m)); });
      if (o.feedback == "state")
        sinks.node->subscribe<kestrel::state_t>(channel::kState, [&](const kestrel::state_t& m) {
          sim::VehicleEstimate e;
          if (!sim::vehicle_estimate(m, e)) return;
          if (!estimate && !o.hold_start_pose) loop->estimate_source_changed();
          estimate = e;
        });
    }
    sinks.node->on_reset([&] { restart = true; });
    sinks.node->set_health(kestrel::process_status_t::STATE_RUNNING, "");
  }
  auto stopping = [&] { return interrupted() || (sinks.node && sinks.node->stopping()); };
  // Lock-step (--lockstep): this process drives the set, and is one of it: its Node, on the
  // same connection, acknowledges the VEHICLE_COMMAND and STATE it consumes, so an event has
  // settled only once the vehicle has its answer.
  std::optional<replay::LockstepDriver> driver;
  if (o.lockstep_s > 0) {
    replay::DriverOptions d;
    d.expect = o.expect;
    d.ack_timeout_s = o.lockstep_s;
    d.record_path = o.record;  // InputError: exit 3
    d.record_inputs = {channel::kGroundTruth};
    const std::regex recorded(o.record_channels);
    d.record_filter = [recorded](const std::string& c) { return std::regex_match(c, recorded); };
    d.dynamic_membership = true;  // a process killed in flight and restarted by kestrel launch
    transport::Node& node = *sinks.node;
    driver.emplace(node.lcm(), [&node](int ms) { node.spin_once(ms); }, d, stopping);
    if (!driver->begin()) return kExitInterrupted;  // PeerError: exit 1
  }
  auto emit = [&](const char* channel, int64_t utime, const std::vector<uint8_t>& bytes) {
    if (driver)
      driver->publish(channel, bytes.data(), bytes.size(), utime,
                      fmt::format("{} at t = {:.3f} s", channel, simulation.seconds(utime)));
    else
      sinks.publish(channel, utime, bytes);
  };

  // The simulated vehicle passes through walls: every contact is reported instead.
  sim::ContactWatch contact(world, o.body_radius_m);
  const int64_t end_utime = so.start_utime + static_cast<int64_t>(o.duration_s * 1e6);
  int64_t frames = 0, imu_samples = 0;
  const auto start = Clock::now();
  auto wall_start = start;
  while (!stopping()) {
    if (restart) {
      simulation.reset();
      contact.reset();
      if (vehicle) {
        vehicle->reset();
        loop.emplace(*vehicle, loop_lookahead_s);  // holding where it starts, until the first STATE
        estimate.reset();
      }
      wall_start = Clock::now();
      restart = false;
    }
    if (loop) {
      // The controller acts on the latest STATE (or the truth) before the next event.
      const double t_next = simulation.seconds(simulation.next_utime());
      const double t_now = std::max(0.0, t_next - vehicle->options().control_period_s);
      sim::VehicleEstimate now;
      if (estimate) {
        now = *estimate;
      } else {
        const sim::PathPoint q = vehicle->point(t_now);
        now = {q.p, q.v, q.yaw};
      }
      loop->advance_to(t_next, now);
    }
    sim::SimEvent e = simulation.next();
    if (e.utime > end_utime) break;
    if (sinks.node && !driver && o.rate > 0) {  // pace: wait for the event's wall time, serving LCM
      const auto due = wall_start + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(simulation.seconds(e.utime) / o.rate));
      while (!stopping() && Clock::now() < due) {
        const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(due - Clock::now()).count();
        sinks.node->spin_once(static_cast<int>(std::max<int64_t>(0, ms)));
      }
    } else if (sinks.node) {
      sinks.node->spin_once(0);
    }
    // Behind the clock (or unpaced), the pacing above waits for nothing: the vehicle's
    // feedback is read here so that it flies on the newest STATE, not a stale one.
    if (sinks.node && vehicle)
      while (!stopping() && sinks.node->lcm().handleTimeout(0) > 0) {
      }
    if (e.kind == sim::SimEvent::kImu) {
      const Eigen::Vector3d p = e.truth.T_world_body.translation();
      if (contact.observe(simulation.seconds(e.utime), p))
        spdlog::warn("the vehicle touches the world at t = {:.3f} s, ({:.2f}, {:.2f}, {:.2f}) (body radius {} m)",
                     simulation.seconds(e.utime), p.x(), p.y(), p.z(), o.body_radius_m);
      // The truth of the instant first: under lock-step everything the IMU sample causes
      // (STATE, a command) then comes after it in any recording, as it did in time.
      emit(channel::kGroundTruth, e.utime, transport::encode_message(sim::ground_truth_message(e.utime, e.truth, &e.imu)));
      emit(channel::kImu, e.utime, transport::encode_message(sim::imu_message(e.utime, e.imu)));
      if (sinks.tum) sinks.tum->add_imu(e.utime, e.imu, e.T_world_camera);
      ++imu_samples;
    } else {
      if (sinks.log || sinks.node)
        emit(channel::kCameraRgbd, e.utime, transport::encode_message(transport::encode_rgbd(e.frame, encoding)));
      if (sinks.tum) sinks.tum->add_frame(e.frame, e.T_world_camera);
      ++frames;
    }
  }
  if (driver) driver->close();
  if (sinks.log) sinks.log->close();
  if (sinks.tum) sinks.tum->close();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::cout << "frames: " << frames << "\n"
            << "imu samples: " << imu_samples << "\n"
            << "simulated seconds: " << o.duration_s << "\n"
            << "wall seconds: " << seconds << "\n"
            << "times real time: " << (seconds > 0 ? o.duration_s / seconds : 0.0) << "\n";
  if (driver) {
    std::cout << "lockstep processes: " << driver->processes().size() << "\n"
              << "lockstep dropped: " << driver->dropped() << "\n"
              << "lockstep joined: " << driver->joined() << "\n";
    for (const auto& [channel, n] : driver->recorded()) std::cout << "recorded " << channel << ": " << n << "\n";
    std::cout << replay::format_latency(driver->latency());
  }
  std::cout << "contacts: " << contact.contacts() << "\n"
            << "min clearance: " << contact.min_clearance_m() << " m\n";
  return stopping() ? kExitInterrupted : kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("sim", "Fly the synthetic world: RGB-D frames, IMU and exact ground truth, live on LCM or to a log / TUM folder");
  Options options;
  add_options(app, options);
  return app.run(argc, argv, [&] { return run(options); });
}
