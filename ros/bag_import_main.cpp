// kestrel-bag-import: a ROS 1 bag of an RGB-D camera (TUM RGB-D's own bags by default) as the
// LCM log kestrel's sources write (CAMERA_RGBD, IMU, GROUND_TRUTH), for replay, the processes
// and eval. The bag is read with librosbag (ros/bag_import.h); the log is written atomically:
// a run that fails leaves no file. See ros/README.md.

#include <console_bridge/console.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/transport/log_file.h"
#include "ros/bag_import.h"
#include "ros/camera_cli.h"

namespace {

using namespace kestrel;

struct Options {
  std::string bag;
  std::string log;
  ros1::BagImportOptions import;
  ros1::CameraTopicCli camera;
};

int run(Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  // ROS's own libraries print their complaints about a damaged bag ("Error: Received an
  // invalid TCPROS header ...") through console_bridge; the exception they then throw ends in
  // kestrel's one error line, which says the same, so they are silenced.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  o.camera.apply(o.import);

  // The log goes to a temporary beside its name and replaces it only once the whole bag was
  // read: a bad bag found half-way (its index, a message) leaves no log that looks whole.
  AtomicFile out(o.log);
  transport::LogWriter log(out.temp_path().empty() ? o.log : out.temp_path());
  ros1::ImportSink sink;
  sink.publish = [&](const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes) {
    log.write(channel, utime, bytes);
  };
  catch_interrupts();
  sink.stopping = [] { return interrupted(); };
  const ros1::BagImportStats s = ros1::import_bag(o.bag, o.import, sink);
  log.close();
  if (s.stopped) {
    // A log of the bag's first part would pass for the whole: nothing is written (the
    // temporary goes with `out`).
    std::cerr << "kestrel-bag-import: interrupted, no log written\n";
    return kExitInterrupted;
  }
  out.commit();

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const PinholeCamera& c = s.camera;
  std::cout << "camera: " << c.width << "x" << c.height << ", fx=" << c.fx << " fy=" << c.fy << " cx=" << c.cx
            << " cy=" << c.cy << (c.distorted() ? " (with distortion)" : "") << ", from "
            << (o.import.intrinsics ? "--intrinsics" : o.import.camera_info_topic) << "\n"
            << "frames written: " << s.frames << " (colour images " << s.colour_images << ", depth images "
            << s.depth_images << ")\n"
            << "colour images without a depth image within " << o.camera.max_dt_s() << " s: " << s.unmatched_colour << "\n"
            << "unused depth images: " << s.unused_depth << "\n"
            << "depth images serving two colour images: " << s.shared_depth << "\n"
            << "images dropped for a repeated stamp: " << s.repeated_stamps << "\n"
            << "CameraInfo messages: " << s.camera_infos << " (" << s.camera_info_changes << " unlike the first)\n"
            << "IMU samples written: " << s.imu_samples << " (" << s.imu_empty << " measuring nothing, skipped; axes "
            << s.imu_axes << ")\n"
            << "ground-truth poses written: " << s.ground_truth_poses << " (" << s.ground_truth << ")\n"
            << "time taken: " << seconds << " s\n";
  if (s.unmatched_colour > 0)
    spdlog::warn("{}: {} colour images have no depth image within {} s and were skipped", o.bag, s.unmatched_colour, o.camera.max_dt_s());
  if (s.camera_info_changes > 0)
    spdlog::warn("{}: {} CameraInfo messages differ from the first, which every frame uses", o.bag, s.camera_info_changes);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("bag-import",
                        "Convert a ROS 1 bag (RGB-D images, CameraInfo, Imu, ground truth) into a kestrel LCM log");
  Options o;
  auto& i = o.import;
  app.add_option("bag", o.bag, "ROS 1 bag file (.bag)")->required();
  app.add_option("--log", o.log, "Write the LCM log here (atomically)")->required();
  o.camera.add_to(app, i);
  app.add_option("--tf-topic", i.tf_topic, "tf2_msgs/TFMessage for the ground truth (and <topic>_static)")
      ->capture_default_str();
  app.add_option("--pose-topic", i.pose_topic, "geometry_msgs/PoseStamped ground truth instead of tf");
  app.add_option("--world-frame", i.world_frame, "Ground truth: the world frame (tf)")->capture_default_str();
  app.add_option("--camera-frame", i.camera_frame, "Ground truth: the frame whose pose is the truth (tf)")
      ->capture_default_str();
  return app.run(argc, argv, [&] { return run(o); });
}
