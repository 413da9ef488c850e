// kestrel-vo as a process, in a private network namespace: a log of synthetic frames (one of
// them corrupt) is replayed in lock-step through it twice; each frame gets one VO_UPDATE with
// the right status and motion, the corrupt one STATUS_BAD_INPUT, and the two replays (with
// a RESET between them) give identical answers. The process takes the camera's profile from
// the sensor model the frames name, unless --sensor says otherwise.

#include <gtest/gtest.h>

#include "common/geometry/se3.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/vo_update_t.hpp"
#include "sensors/builtin_profiles.h"
#include "test/support/test_support.h"
#include "test/vo/synthetic_scene.h"
#include "vo/options.h"
#include "vo/sensor_profile.h"

namespace kestrel::vo {
namespace {

constexpr int kFrames = 5;
constexpr int kCorrupt = 3;  // this frame's depth is cut short on the wire

Eigen::Isometry3d truth(int k) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.01 * k, -0.005 * k, 0.0);
  return T;
}

void write_input_log(const std::string& path) {
  const test::SyntheticScene scene(31);
  transport::LogWriter log(path);
  for (int k = 0; k < kFrames; ++k) {
    const RgbdFrame frame = scene.render(truth(k), test::test_camera(), 1000000 + 33333 * k);
    kestrel::rgbd_frame_t message = transport::encode_rgbd(frame);
    if (k == kCorrupt) message.depth.resize(message.depth.size() / 2);
    message.depth_size = static_cast<int32_t>(message.depth.size());
    log.write_message(channel::kCameraRgbd, frame.utime, message);
  }
  log.close();
}

std::vector<kestrel::vo_update_t> updates(const std::string& path) {
  return transport::read_messages<kestrel::vo_update_t>(path, channel::kVoUpdate);
}

TEST(VoProcess, LockStepReplayGivesOneUpdatePerFrameAndRepeats) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
  write_input_log(in);
  const std::string vo = kestrel::test::tool("vo").string(), replay = kestrel::test::tool("replay").string();
  const std::string script =
      "'" + vo + "' -q & VO=$!; "
      "'" + replay + "' '" + in + "' --expect vo --record '" + (dir / "a.lcmlog").string() + "' >/dev/null && "
      "'" + replay + "' '" + in + "' --expect vo --record '" + (dir / "b.lcmlog").string() + "' >/dev/null; "
      "R=$?; kill $VO; wait $VO; exit $R";
  const kestrel::test::RunResult r =
      kestrel::test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const auto a = updates((dir / "a.lcmlog").string()), b = updates((dir / "b.lcmlog").string());
  ASSERT_EQ(a.size(), size_t(kFrames));
  ASSERT_EQ(b.size(), a.size());
  for (int k = 0; k < kFrames; ++k) {
    const auto& u = a[size_t(k)];
    EXPECT_EQ(u.utime, 1000000 + 33333 * k);
    if (k == 0) {
      EXPECT_EQ(u.status, kestrel::vo_update_t::STATUS_NO_REFERENCE);
      EXPECT_TRUE(u.flags & kestrel::vo_update_t::FLAG_NEW_REFERENCE);
    } else if (k == kCorrupt) {
      EXPECT_EQ(u.status, kestrel::vo_update_t::STATUS_BAD_INPUT);
    } else {
      ASSERT_EQ(u.status, kestrel::vo_update_t::STATUS_OK) << "frame " << k;
      const Eigen::Isometry3d T = transport::from_message(u.T_reference_current, "VO_UPDATE");
      const Eigen::Isometry3d T_true = truth(0).inverse() * truth(k);  // reference: the first frame
      EXPECT_EQ(u.reference_utime, 1000000);
      EXPECT_LT(se3::translation_distance(T, T_true), 0.003) << "frame " << k;
      EXPECT_GT(u.covariance[0], 0.0);
      // The floors the covariance includes, for a chain to count once (the process's defaults).
      EXPECT_DOUBLE_EQ(u.translation_floor, VoOptions{}.covariance.translation_floor_m);
      EXPECT_DOUBLE_EQ(u.rotation_floor, VoOptions{}.covariance.rotation_floor_rad);
      EXPECT_GE(u.covariance[0], u.translation_floor * u.translation_floor);
      EXPECT_GT(u.num_reprojection_inliers, 50);
      EXPECT_GE(u.elapsed_ms, 0.0f);
    }
    // The replay after a RESET starts over and gives the same answers.
    EXPECT_EQ(b[size_t(k)].status, u.status);
    EXPECT_EQ(b[size_t(k)].reference_utime, u.reference_utime);
    EXPECT_EQ(b[size_t(k)].num_inliers, u.num_inliers);
  }
}

// Frames 0-2 name a Kinect, 3-5 the simulator: the updates carry the named profile's floors,
// and the change of camera restarts the odometry (frame 3 has no reference). With --sensor
// every frame gets that profile and nothing restarts.
TEST(VoProcess, TakesTheCameraProfileTheFramesName) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
  {
    const test::SyntheticScene scene(31);
    transport::LogWriter log(in);
    for (int k = 0; k < 6; ++k) {
      RgbdFrame frame = scene.render(truth(k), test::test_camera(), 1000000 + 33333 * k);
      frame.sensor = k < 3 ? sensor_model::kKinect1 : sensor_model::kSimulator;
      log.write_message(channel::kCameraRgbd, frame.utime, transport::encode_rgbd(frame));
    }
  }
  const std::string vo = kestrel::test::tool("vo").string(), replay = kestrel::test::tool("replay").string();
  const std::string script =
      "'" + vo + "' -q & VO=$!; "
      "'" + replay + "' '" + in + "' --expect vo --record '" + (dir / "named.lcmlog").string() + "' >/dev/null; "
      "R=$?; kill $VO; wait $VO; [ $R = 0 ] || exit $R; "
      "'" + vo + "' -q --sensor kinect1 & VO=$!; "
      "'" + replay + "' '" + in + "' --expect vo --record '" + (dir / "told.lcmlog").string() + "' >/dev/null; "
      "R=$?; kill $VO; wait $VO; exit $R";
  const kestrel::test::RunResult r =
      kestrel::test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const VoOptions simulator = with_sensor(sensors::builtin_profile("simulator"), VoOptions{}),
                  kinect = with_sensor(sensors::builtin_profile("kinect1"), VoOptions{});
  ASSERT_NE(simulator.covariance.translation_floor_m, kinect.covariance.translation_floor_m);
  const auto named = updates((dir / "named.lcmlog").string()), told = updates((dir / "told.lcmlog").string());
  ASSERT_EQ(named.size(), 6u);
  ASSERT_EQ(told.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const auto& u = named[size_t(k)];
    const bool first_of_camera = k == 0 || k == 3;
    EXPECT_EQ(u.status, first_of_camera ? kestrel::vo_update_t::STATUS_NO_REFERENCE : kestrel::vo_update_t::STATUS_OK)
        << "frame " << k;
    if (!first_of_camera) {
      EXPECT_DOUBLE_EQ(u.translation_floor, (k < 3 ? kinect : simulator).covariance.translation_floor_m) << k;
      EXPECT_DOUBLE_EQ(u.rotation_floor, (k < 3 ? kinect : simulator).covariance.rotation_floor_rad) << k;
    }
    const auto& v = told[size_t(k)];
    EXPECT_EQ(v.status, k == 0 ? kestrel::vo_update_t::STATUS_NO_REFERENCE : kestrel::vo_update_t::STATUS_OK) << k;
    if (k > 0) {
      EXPECT_DOUBLE_EQ(v.translation_floor, kinect.covariance.translation_floor_m) << k;
    }
  }
}

}  // namespace
}  // namespace kestrel::vo
