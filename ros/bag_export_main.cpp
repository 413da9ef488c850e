// kestrel-bag-export: kestrel's output in a log (STATE, ...) as a ROS 1 bag that rviz and
// other ROS tools read. The log is read with kestrel's LogReader, the bag written with
// librosbag (ros/bag_export.h), atomically: a run that fails leaves no file. See ros/README.md.

#include <console_bridge/console.h>

#include <chrono>
#include <iostream>

#include <rosbag/bag.h>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "ros/bag_export.h"

namespace {

using namespace kestrel;

struct Options {
  std::string log;
  std::string bag;
  ros1::BagExportOptions exp;
};

int run(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  // The bag goes to a temporary beside its name and replaces it only once the whole log was
  // read: a log found bad half-way, or none of the channels, leaves no bag.
  AtomicFile out(o.bag);
  ros1::BagExportStats s;
  {
    rosbag::Bag bag;
    try {
      // in-place: AtomicFile's temporary (or a device target), committed once the bag is whole
      bag.open(out.temp_path().empty() ? o.bag : out.temp_path(), rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      throw InputError(o.bag + ": cannot write the bag: " + e.what());
    }
    catch_interrupts();
    s = ros1::export_log(o.log, o.exp, bag, [] { return interrupted(); });
    bag.close();
  }
  if (s.stopped) {
    std::cerr << "kestrel-bag-export: interrupted, no bag written\n";
    return kExitInterrupted;
  }
  out.commit();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "log events read: " << s.log_events << "\n";
  for (const auto& [topic, n] : s.messages) std::cout << topic << ": " << n << " messages\n";
  std::cout << "messages written: " << s.total() << "\n"
            << "frames: " << o.exp.world_frame << " -> " << o.exp.body_frame << " -> " << o.exp.camera_frame << "\n"
            << "VO frames without a pose: " << s.vo_without_estimate << " (out of order, skipped: " << s.vo_out_of_order
            << ")\n"
            << "ground truth of: " << (s.truth_of.empty() ? "none" : s.truth_of) << "\n"
            << "time taken: " << seconds << " s\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("bag-export", "Write kestrel's output in an LCM log (STATE, ...) as a ROS 1 bag");
  Options o;
  auto& e = o.exp;
  app.add_option("log", o.log, "kestrel LCM log (a recording of the system's output)")->required();
  app.add_option("--bag", o.bag, "Write the ROS 1 bag here (atomically)")->required();
  app.add_option("--world-frame", e.world_frame, "tf frame of the estimator's world (STATE's)")->capture_default_str();
  app.add_option("--body-frame", e.body_frame, "tf frame of the vehicle body")->capture_default_str();
  app.add_option("--camera-frame", e.camera_frame, "tf frame of the RGB camera (optical)")->capture_default_str();
  app.add_option("--vo-frame", e.vo_frame, "frame_id of /kestrel/vo (the VO's own world: its first camera frame)")
      ->capture_default_str();
  app.add_option("--truth-frame", e.truth_frame, "frame_id of /kestrel/ground_truth (the truth's world)")
      ->capture_default_str();
  app.add_flag("--map-free", e.map_free, "Also MAP_OCTOMAP's free cells, as /kestrel/map/free (many points)");
  app.add_flag("--images", e.images, "Also CAMERA_RGBD: colour (rgb8), depth (16UC1 mm), CameraInfo (big)");
  return app.run(argc, argv, [&] { return run(o); });
}
