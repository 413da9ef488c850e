// The TUM driver on the real sequences in ../shared/data (skipped when absent): the player's
// log against the files read independently, the association TUM's rule gives, and the
// accelerometer axes against the motion capture.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "common/image/image_io.h"
#include "common/numbers.h"
#include "common/text.h"
#include "common/time.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/tum/playback.h"
#include "drivers/tum/tum_sequence.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "test/support/figures.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

// First field of every data line of a TUM text file, exact, and the second (file name).
std::vector<std::pair<int64_t, std::string>> stamps(const std::filesystem::path& path) {
  std::vector<std::pair<int64_t, std::string>> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (is_comment_or_blank(line)) continue;
    const auto f = split_fields(line);
    out.emplace_back(*parse_seconds(f[0]), std::string(f[1]));
  }
  return out;
}

TEST(TumData, Fr1RpyLogHoldsAllFramesImuAndGroundTruthInTimeOrder) {
  KESTREL_REQUIRE_TUM(seq, "rgbd_dataset_freiburg1_rpy");
  test::TempDir dir;
  const auto log = dir / "rpy.lcmlog";
  const auto r = test::run({test::tool("tum-play").string(), seq.string(), "--log", log.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const test::Figure& published = test::figure("tum.association.fr1_rpy");
  EXPECT_NE(r.out.find("frames published: " + std::to_string(std::lround(published.value)) + "\n"), std::string::npos)
      << r.out;

  const auto rgb = stamps(seq / "rgb.txt");
  const auto depth = stamps(seq / "depth.txt");
  const auto accel = stamps(seq / "accelerometer.txt");
  const auto gt = stamps(seq / "groundtruth.txt");
  ASSERT_EQ(rgb.size(), 200u);
  auto within = [&](int64_t t) { return t >= rgb.front().first && t <= rgb.back().first; };
  const auto in_window = [&](const auto& list) {
    return std::count_if(list.begin(), list.end(), [&](const auto& s) { return within(s.first); });
  };
  // The poses from the last at or before 50 ms before the first frame to the first at or
  // after 50 ms past the last (the depth's capture precedes the colour stamp).
  const auto bracketing = [&](const auto& list) {
    const int64_t from = rgb.front().first - tum::kGroundTruthMarginUs, to = rgb.back().first + tum::kGroundTruthMarginUs;
    const auto n = std::count_if(list.begin(), list.end(), [&](const auto& s) { return s.first >= from && s.first <= to; });
    const bool at_from = std::any_of(list.begin(), list.end(), [&](const auto& s) { return s.first == from; });
    const bool at_to = std::any_of(list.begin(), list.end(), [&](const auto& s) { return s.first == to; });
    return n + (at_from ? 0 : 1) + (at_to ? 0 : 1);
  };

  transport::LogReader reader(log.string());
  int64_t last = 0, frames = 0, imu = 0, poses = 0;
  while (auto e = reader.next()) {
    ASSERT_GE(e->timestamp, last);
    last = e->timestamp;
    if (e->channel == channel::kCameraRgbd) {
      const RgbdFrame f = transport::decode_rgbd(
          transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), e->channel), "log");
      // fr1_rpy's lists pair up one to one, in order.
      ASSERT_EQ(f.seq, frames);
      EXPECT_EQ(f.utime, rgb[static_cast<size_t>(frames)].first);
      EXPECT_EQ(f.depth_utime, depth[static_cast<size_t>(frames)].first);
      EXPECT_EQ(f.camera.fx, 517.3);
      if (frames == 0 || frames == 199) {
        // The images, read here with OpenCV directly.
        cv::Mat bgr = image::read_image((seq / rgb[static_cast<size_t>(frames)].second).string());
        cv::Mat expected_rgb;
        cv::cvtColor(bgr, expected_rgb, cv::COLOR_BGR2RGB);
        EXPECT_EQ(cv::norm(f.rgb, expected_rgb, cv::NORM_INF), 0.0);
        cv::Mat raw = image::read_image((seq / depth[static_cast<size_t>(frames)].second).string());
        cv::Mat expected_mm;
        raw.convertTo(expected_mm, CV_32F, 0.2);  // 5000 units per metre
        cv::Mat got_mm;
        f.depth_mm.convertTo(got_mm, CV_32F);
        EXPECT_LE(cv::norm(got_mm, expected_mm, cv::NORM_INF), 0.5);
      }
      ++frames;
    } else if (e->channel == channel::kImu) {
      const auto m = transport::decode_message<kestrel::imu_t>(e->data.data(), e->data.size(), e->channel);
      EXPECT_EQ(m.utime, e->timestamp);
      ++imu;
    } else {
      ASSERT_EQ(e->channel, channel::kGroundTruth);
      ++poses;
    }
  }
  EXPECT_EQ(reader.damage_report(), "");
  EXPECT_TRUE(test::within_limit(static_cast<double>(frames), published));
  EXPECT_EQ(imu, in_window(accel));
  EXPECT_EQ(poses, bracketing(gt));
  EXPECT_GT(imu, 3000);  // about 500 Hz over 6.6 s
  EXPECT_GT(poses, 600);  // 100 Hz
}

TEST(TumData, Fr1XyzAssociationFollowsTumsRule) {
  KESTREL_REQUIRE_TUM(seq, "rgbd_dataset_freiburg1_xyz");
  const tum::TumSequence s(seq.string());
  // The rule applied to these lists by an independent script: every RGB image has a depth
  // image within 20 ms; image 30 (at 1305031105.675166) shares image 29's, which TUM's
  // one-to-one associate.py gives to image 29 alone (the depth at .627128 goes unused).
  EXPECT_EQ(s.association().rgb_images, 190u);
  EXPECT_TRUE(test::within_limit(static_cast<double>(s.association().frames), test::figure("tum.association.fr1_xyz")));
  EXPECT_EQ(s.association().unmatched_rgb, 0u);
  EXPECT_EQ(s.association().unused_depth, 1u);
  EXPECT_EQ(s.association().shared_depth, 1u);
  EXPECT_EQ(s.rgb_index(30), 30u);
  EXPECT_EQ(s.utime(29), 1305031105643273);
  EXPECT_EQ(s.depth_utime(29), 1305031105659104);
  EXPECT_EQ(s.utime(30), 1305031105675166);
  EXPECT_EQ(s.depth_utime(30), 1305031105659104);
  EXPECT_EQ(s.camera_model(), tum::TumCamera::kFreiburg1);
}

// The accelerometer at rest-ish reads the specific force; in the camera frame that is
// R_world_camera^T * (0, 0, g) with the motion-capture world z up. Hand-held motion adds
// about 1 m/s^2, so compare directions on average.
double mean_angle_deg(const tum::TumSequence& s, bool convert) {
  double sum = 0.0;
  int n = 0;
  for (const auto& a : s.accelerometer()) {
    const auto T = s.ground_truth().at(a.utime, 20000);
    if (!T) continue;
    const Eigen::Vector3d predicted = T->linear().transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d measured = convert ? kinect::accel_to_camera(a.accel_kinect) : a.accel_kinect;
    sum += std::acos(std::clamp(predicted.dot(measured.normalized()), -1.0, 1.0)) * 180.0 / kPi;
    ++n;
  }
  EXPECT_GT(n, 1000);
  return sum / n;
}

TEST(TumData, AccelerometerAxesMatchTheMotionCapture) {
  for (const char* name : {"rgbd_dataset_freiburg1_xyz", "rgbd_dataset_freiburg1_rpy"}) {
    KESTREL_REQUIRE_TUM(seq, name);
    const tum::TumSequence s(seq.string());
    const double converted = mean_angle_deg(s, true);
    const double raw = mean_angle_deg(s, false);
    RecordProperty(std::string(name) + "_mean_angle_deg", std::to_string(converted));
    // The camera-frame reading points where gravity says.
    EXPECT_TRUE(test::within_limit(converted * kDegree, test::figure("tum.accelerometer.published_axes"))) << name;
    EXPECT_GT(raw, 45.0) << name;       // the raw axes do not
  }
}

}  // namespace
}  // namespace kestrel
