// kestrel-tum-to-fakenect: turns a TUM RGB-D sequence into a fakenect recording, so that the
// unchanged kestrel-kinect driver can be run on it (LD_LIBRARY_PATH=<fakenect>,
// FAKENECT_PATH=OUT). Depth is un-registered from the RGB camera into the IR camera and
// converted to raw 11-bit values with the same KinectCalibration that kestrel-kinect then
// uses to bring it back; OUT/kestrel-kinect.ini holds that calibration for
// `kestrel-kinect --config OUT/kestrel-kinect.ini`. See README.md.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <tuple>

#include <opencv2/core.hpp>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "drivers/kinect/calibration_options.h"
#include "drivers/kinect/depth_registration.h"
#include "drivers/kinect/fakenect_dump.h"
#include "drivers/tum/playback.h"
#include "drivers/tum/tum_sequence.h"

namespace {

using namespace kestrel;

struct Options {
  std::string folder;
  std::string out;
  double start_s = 0.0;
  double duration_s = 0.0;
  int64_t frames = 0;
  double max_dt_s = 0.02;
  double depth_scale = 1.0;
  bool no_accel = false;
  kinect::CalibrationOptions calibration;
};

void add_options(cli::App& app, Options& o) {
  app.add_option("folder", o.folder, "TUM RGB-D sequence folder")->required();
  app.add_option("out", o.out, "Folder for the fakenect recording (created; must hold no INDEX.txt)")->required();
  app.add_option("--start", o.start_s, "Skip this many seconds after the first frame")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "Take this many seconds (0 = to the end)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--frames", o.frames, "Take at most this many frames (0 = all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--max-dt", o.max_dt_s, "Largest RGB-depth time difference of a frame, seconds")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--depth-scale", o.depth_scale, "Depth scale correction (fr1: about 1.035)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_flag("--no-accel", o.no_accel, "Leave the accelerometer out");
  o.calibration.add_to(app);
  app.get_option("--rgb-intrinsics")
      ->description("RGB camera fx,fy,cx,cy (default: TUM's values for the sequence's camera)");
}

struct Entry {
  int64_t utime;
  int order;  // at equal times: accelerometer, then depth, then RGB
  char type;
  size_t index;
};

// The calibration as kestrel-kinect options, so the driver undoes exactly this conversion.
void write_driver_config(const std::string& path, const kinect::KinectCalibration& c, bool identity) {
  AtomicFile file(path);  // a failed run leaves no cut configuration that looks whole
  std::ostream& out = file.stream();
  out << std::setprecision(17);
  auto list = [&](const char* key, std::initializer_list<double> v) {
    out << key << "=[";
    const char* sep = "";
    for (double x : v) {
      out << sep << x;
      sep = ",";
    }
    out << "]\n";
  };
  out << "# kestrel-kinect configuration matching this fakenect recording\n";
  list("rgb-intrinsics", {c.rgb.fx, c.rgb.fy, c.rgb.cx, c.rgb.cy});
  list("ir-intrinsics", {c.ir.fx, c.ir.fy, c.ir.cx, c.ir.cy});
  const Eigen::Matrix3d R = c.T_ir_rgb.linear();
  list("rgb-in-ir-rotation", {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)});
  const Eigen::Vector3d t = c.T_ir_rgb.translation();
  list("rgb-in-ir-translation", {t.x(), t.y(), t.z()});
  list("disparity", {c.disparity.a, c.disparity.b});
  out << "identity-calibration=" << (identity ? "true" : "false") << "\n";
  file.commit();
}

int run(const Options& o, bool rgb_intrinsics_given) {
  const auto t0 = std::chrono::steady_clock::now();
  tum::SequenceOptions so;
  so.max_time_difference_us = std::llround(o.max_dt_s * 1e6);
  so.depth_scale_correction = o.depth_scale;
  const tum::TumSequence sequence(o.folder, so);
  if (sequence.camera().width != 640 || sequence.camera().height != 480) {
    // A Kinect's dump (fakenect_dump.h) is 640x480; anything else would fail half-written.
    throw InputError(o.folder + ": the images are " + std::to_string(sequence.camera().width) + "x" +
                     std::to_string(sequence.camera().height) + " (its camera.txt), a Kinect dump is 640x480");
  }

  kinect::KinectCalibration calibration = o.calibration.calibration();
  if (!rgb_intrinsics_given) {
    calibration.rgb = sequence.camera();
    if (o.calibration.identity) calibration.ir = calibration.rgb;
  }
  const kinect::DepthRegistration registration(calibration);

  tum::PlaybackWindow window;
  window.start_s = o.start_s;
  window.duration_s = o.duration_s;
  window.imu = !o.no_accel;
  window.ground_truth = false;
  auto events = tum::playback_schedule(sequence, window);
  if (o.frames > 0) {
    int64_t seen = 0;
    size_t end = 0;
    while (end < events.size()) {
      if (events[end].kind == tum::EventKind::kFrame && seen++ == o.frames) break;
      ++end;
    }
    // Keep the accelerometer only up to the last frame taken.
    while (end > 0 && events[end - 1].kind != tum::EventKind::kFrame) --end;
    events.resize(end);
  }
  if (events.empty()) throw CLI::ValidationError("--start/--duration", "no frame of the sequence lies in that window");

  // Depth and RGB of a frame are written at their own time stamps, so frames interleave.
  std::vector<Entry> entries;
  for (const auto& e : events) {
    if (e.kind == tum::EventKind::kImu) {
      entries.push_back({e.utime, 0, 'a', e.index});
    } else {
      entries.push_back({sequence.depth_utime(e.index), 1, 'd', e.index});
      entries.push_back({sequence.utime(e.index), 2, 'r', e.index});
    }
  }
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.utime, a.order) < std::tie(b.utime, b.order);
  });

  kinect::FakenectDumpWriter dump(o.out);
  std::map<size_t, RgbdFrame> decoded;  // frames with one of their two entries still to write
  std::set<int64_t> written_depth;      // depth time stamps written
  int64_t frames = 0, accel = 0, depth_in = 0, depth_out = 0;
  for (const Entry& e : entries) {
    if (e.type == 'a') {
      dump.add_accel(e.utime, sequence.accelerometer()[e.index].accel_kinect);
      ++accel;
      continue;
    }
    auto it = decoded.find(e.index);
    if (it == decoded.end()) it = decoded.emplace(e.index, sequence.frame(e.index)).first;
    if (e.type == 'd' && !written_depth.insert(e.utime).second) {
      it->second.depth_mm.release();  // shared with the previous frame (tum/association.h): the Kinect sent it once
    } else if (e.type == 'd') {
      const cv::Mat raw = registration.unregister_mm(it->second.depth_mm);
      depth_in += cv::countNonZero(it->second.depth_mm);
      depth_out += static_cast<int64_t>(raw.total()) - cv::countNonZero(raw == kinect::DisparityModel::kNoReading);
      dump.add_depth(e.utime, raw);
      it->second.depth_mm.release();
    } else {
      dump.add_rgb(e.utime, it->second.rgb);
      it->second.rgb.release();
      ++frames;
    }
    if (it->second.rgb.empty() && it->second.depth_mm.empty()) decoded.erase(it);
  }
  dump.close();
  const std::string config = (std::filesystem::path(o.out) / "kestrel-kinect.ini").string();
  write_driver_config(config, calibration, o.calibration.identity);

  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "frames written: " << frames << "\n"
            << "accelerometer samples written: " << accel << "\n"
            << "depth pixels kept by un-registering: " << depth_out << " of " << depth_in << "\n"
            << "driver configuration: " << config << "\n"
            << "time taken: " << seconds << " s\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("tum-to-fakenect", "Write a TUM RGB-D sequence as a fakenect recording for kestrel-kinect");
  Options options;
  add_options(app, options);
  return app.run(argc, argv, [&] { return run(options, app.count("--rgb-intrinsics") > 0); });
}
