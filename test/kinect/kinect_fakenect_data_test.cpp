// The key test of the Kinect driver, on real data: frames of TUM fr1_xyz are written as a
// fakenect recording (depth un-registered into the IR camera and turned into raw 11-bit
// values), the unchanged kestrel-kinect replays it through Debian's fakenect library inside a
// private network namespace, and what it publishes must be the dataset's frames: RGB byte
// for byte, depth within the 11-bit quantisation where both have a reading.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/kinect/disparity_model.h"
#include "drivers/kinect/kinect_calibration.h"
#include "drivers/tum/tum_camera.h"
#include "drivers/tum/tum_sequence.h"
#include "kestrel/imu_t.hpp"
#include "test/kinect/fakenect_support.h"
#include "test/support/figures.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

struct Comparison {
  int frames = 0;
  int imu = 0;
  int imu_matching = 0;
  int64_t dataset_valid = 0;  // dataset pixels with a reading the 11-bit model can express
  int64_t outside_view = 0;   // ... whose surface point the IR camera does not see
  int64_t lost = 0;           // ... in its view, for which the driver published none
  int64_t both = 0;
  int64_t outside = 0;        // both valid, error beyond the quantisation
  int64_t invented = 0;       // driver reading where the dataset has none
  double worst_ratio = 0.0;   // largest error / tolerance
};

// Writes the first `frames` frames of fr1_xyz as a recording, replays it, and compares.
// `calibration` is what both tools are given; `cal` the same as a KinectCalibration.
Comparison round_trip(const std::filesystem::path& seq, int frames, const std::vector<std::string>& calibration,
                      const kinect::KinectCalibration& cal) {
  test::TempDir dir;
  const auto dump = dir / "dump";
  std::vector<std::string> w = {test::tool("tum-to-fakenect").string(), seq.string(), dump.string(), "--frames",
                                std::to_string(frames)};
  w.insert(w.end(), calibration.begin(), calibration.end());
  const auto written = test::run(w);
  EXPECT_EQ(written.exit_code, 0) << written.err;

  // --log: the driver needs no network at all; it still runs in a namespace of its own where
  // one can be made, so that nothing it does can reach a real interface.
  const auto log = dir / "kinect.lcmlog";
  std::vector<std::string> args = {"--config", (dump / "kestrel-kinect.ini").string(), "--log", log.string(),
                                   "--frames", std::to_string(frames)};
  test::RunResult r;
  if (test::can_isolate_network()) {
    std::vector<std::string> argv = {test::tool("isolated").string(), "--", "env",
                                     "LD_LIBRARY_PATH=" + test::fakenect_library_dir(), "FAKENECT_PATH=" + dump.string(),
                                     test::tool("kinect").string()};
    argv.insert(argv.end(), args.begin(), args.end());
    r = test::run(argv);
  } else {
    r = test::run_kinect(dump, args);
  }
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::cout << r.out;

  const tum::TumSequence s(seq.string());
  const kinect::DisparityModel model;
  std::set<std::vector<long>> accel;  // the dataset's readings, in the camera frame, in um/s^2
  for (const auto& a : s.accelerometer()) {
    const Eigen::Vector3d c = kinect::accel_to_camera(a.accel_kinect);
    accel.insert({std::lround(c.x() * 1e6), std::lround(c.y() * 1e6), std::lround(c.z() * 1e6)});
  }
  Comparison c;
  transport::LogReader reader(log.string());
  while (auto e = reader.next()) {
    if (e->channel == channel::kImu) {
      const auto m = transport::decode_message<kestrel::imu_t>(e->data.data(), e->data.size(), e->channel);
      ++c.imu;
      c.imu_matching += accel.count({std::lround(m.linear_acceleration[0] * 1e6), std::lround(m.linear_acceleration[1] * 1e6),
                                     std::lround(m.linear_acceleration[2] * 1e6)}) > 0;
      continue;
    }
    const RgbdFrame got = transport::decode_rgbd(
        transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), e->channel), "log");
    const RgbdFrame want = s.frame(static_cast<size_t>(c.frames));
    EXPECT_EQ(got.seq, c.frames);
    EXPECT_EQ(cv::norm(got.rgb, want.rgb, cv::NORM_INF), 0.0) << "RGB of frame " << c.frames << " differs";
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int z_mm = want.depth_mm.at<uint16_t>(v, u);
        const int g_mm = got.depth_mm.at<uint16_t>(v, u);
        if (z_mm == 0 || model.raw(z_mm * 1e-3) == kinect::DisparityModel::kNoReading) {
          c.invented += g_mm != 0;
          continue;
        }
        ++c.dataset_valid;
        const Eigen::Vector3d p_rgb = want.camera.backproject(u, v, z_mm * 1e-3);
        const Eigen::Vector2d px = cal.ir.project(cal.T_ir_rgb * p_rgb);
        if (!cal.ir.contains(px.x(), px.y())) {
          ++c.outside_view;
          continue;
        }
        if (g_mm == 0) {
          ++c.lost;
          continue;
        }
        ++c.both;
        const double tolerance = 0.5 * model.step_at(z_mm * 1e-3) * 1e3 + 1.0;
        const double ratio = std::abs(g_mm - z_mm) / tolerance;
        c.worst_ratio = std::max(c.worst_ratio, ratio);
        c.outside += ratio > 1.0;
      }
    }
    ++c.frames;
  }
  EXPECT_EQ(reader.damage_report(), "");
  return c;
}

void report(const char* what, const Comparison& c) {
  std::cout << what << ": " << c.frames << " frames; of " << c.dataset_valid << " dataset depth readings "
            << 100.0 * c.outside_view / c.dataset_valid << " % lie outside the IR camera's view; of the rest "
            << 100.0 * c.lost / (c.dataset_valid - c.outside_view) << " % are lost, "
            << 100.0 * c.outside / std::max<int64_t>(c.both, 1) << " % of the rest beyond the 11-bit quantisation "
            << "(worst " << c.worst_ratio << " x), " << c.invented << " readings where the dataset has none; "
            << c.imu_matching << " of " << c.imu << " IMU samples are dataset readings\n";
}

TEST(KinectFakenectData, IdentityCalibrationIsExactWithinQuantisation) {
  KESTREL_REQUIRE_TUM(seq, "rgbd_dataset_freiburg1_xyz");
  KESTREL_REQUIRE_FAKENECT();
  const PinholeCamera fr1 = tum::camera_intrinsics(tum::TumCamera::kFreiburg1);
  const Comparison c = round_trip(seq, 20, {"--identity-calibration"}, kinect::KinectCalibration::identity(fr1));
  report("identity calibration", c);
  EXPECT_EQ(c.frames, 20);
  EXPECT_EQ(c.outside_view, 0);
  EXPECT_EQ(c.lost, 0);
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.outside) / std::max<int64_t>(c.both, 1),
                                 test::figure("kinect.identity.beyond_quantisation")));
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.invented) / c.dataset_valid,
                                 test::figure("kinect.identity.invented")));
  EXPECT_GT(c.dataset_valid, 20 * 640 * 480 / 2);
  EXPECT_EQ(c.imu_matching, c.imu);
  EXPECT_GT(c.imu, 40);  // 100 Hz over 0.67 s
}

TEST(KinectFakenectData, KinectCalibrationLosesOnlyEdgesAndTheIrCamerasNarrowerView) {
  KESTREL_REQUIRE_TUM(seq, "rgbd_dataset_freiburg1_xyz");
  KESTREL_REQUIRE_FAKENECT();
  // Burrus's IR camera and IR-RGB transform, TUM's fr1 RGB camera (the tool's default).
  kinect::KinectCalibration cal = kinect::KinectCalibration::standard();
  cal.rgb = tum::camera_intrinsics(tum::TumCamera::kFreiburg1);
  const Comparison c = round_trip(seq, 45, {}, cal);
  report("Kinect calibration", c);
  EXPECT_EQ(c.frames, 45);
  // The IR camera (fx 594) sees less than the RGB camera (fx 517): about a fifth of the RGB
  // image lies outside its view and has no depth after registration, as on a real Kinect.
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.outside_view) / c.dataset_valid,
                                 test::figure("kinect.burrus.outside_view")));
  // Inside its view only occlusion edges lose readings: where the un-registering z-buffer
  // kept the nearer of two surfaces, the farther one has no IR pixel left.
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.lost) / (c.dataset_valid - c.outside_view),
                                 test::figure("kinect.burrus.lost")));
  // Two nearest-pixel resamplings move a reading by up to a pixel: at depth edges that is a
  // jump to the other surface. Elsewhere the error stays within the quantisation.
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.outside) / c.both,
                                 test::figure("kinect.burrus.beyond_quantisation")));
  EXPECT_TRUE(test::within_limit(static_cast<double>(c.invented) / c.dataset_valid,
                                 test::figure("kinect.burrus.invented")));
  EXPECT_EQ(c.imu_matching, c.imu);
}

}  // namespace
}  // namespace kestrel
