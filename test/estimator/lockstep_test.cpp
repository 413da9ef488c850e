// kestrel-estimator under lock-step replay, in a private network namespace: a synthesised log
// (IMU, VO_UPDATE, a late SLAM_CORRECTION, a duplicate, a NaN sample and a corrupt message)
// replayed twice through one running estimator (RESET between) gives byte-identical STATE
// recordings, one STATE per accepted IMU sample, and the last state equals the library's
// (kestrel estimate's) on the same log. This is the whole process path: LCM decode, the
// message conversions, Node's rejection of bad messages, acks and RESET. An IMU without a gyro
// runs the visual-only estimator, or, in --mode imu, is refused with the heartbeat saying why.
// The processes run under a LiveSystem (test/support/live_system.h), which hears their
// heartbeats itself: a test waits for the heartbeat it needs rather than for a fixed time.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <sstream>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "estimator/log_run.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/state_t.hpp"
#include "test/estimator/synthetic_log.h"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel::estimator {
namespace {

using kestrel::test::LiveSystem;

TEST(EstimatorProcess, LockStepReplayIsDeterministicResetsAndEqualsTheLibrary) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  kestrel::test::TempDir dir;
  LiveSystem live(dir.path() / "live", {});
  const std::string in = (dir / "in.lcmlog").string();
  test::write_log(in, 3.0, true);
  live.start("estimator", {kestrel::test::tool("estimator").string(), "--init-yaw", "0.3"});
  ASSERT_EQ(live.replay(in, "estimator", dir / "a.lcmlog", {}, 240.0), 0) << live.output("replay");
  ASSERT_EQ(live.replay(in, "estimator", dir / "b.lcmlog", {}, 240.0), 0) << live.output("replay");
  ASSERT_EQ(live.stop("estimator"), 0) << live.output("estimator");
  const std::string a = kestrel::test::read_file(dir / "a.lcmlog");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, kestrel::test::read_file(dir / "b.lcmlog")) << "the second replay (after RESET) must publish the same states";

  EstimatorOptions options;
  options.init.yaw = 0.3;
  const LogRunResult expected = run_log(in, options);
  transport::LogReader recorded((dir / "a.lcmlog").string());
  std::optional<kestrel::state_t> last;
  size_t states = 0;
  while (auto event = recorded.next()) {
    if (event->channel != channel::kState) continue;
    last = transport::decode_message<kestrel::state_t>(event->data.data(), event->data.size(), "STATE");
    EXPECT_EQ(last->seq, static_cast<int64_t>(states));
    ++states;
  }
  ASSERT_EQ(states, expected.trajectory.size());
  ASSERT_TRUE(last.has_value());
  const StampedPose& want = expected.trajectory.poses().back();
  EXPECT_EQ(last->utime, want.utime);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(last->T_world_body.position[i], want.T.translation()[i], 1e-12);
  EXPECT_EQ(last->cov_dim, 15);
}

// An IMU without a gyro (a TUM recording, a Kinect: the accelerometer only) and VO. By
// default the estimator runs on the VO alone: a STATE per VO update, marked visual-only, the
// heartbeat RUNNING and saying so; the states equal the offline run's (kestrel estimate).
// With --mode imu every sample is refused, no STATE is published, and the heartbeat says why
// instead of "initialising".
TEST(EstimatorProcess, AnImuWithoutAGyroRunsVisualOnlyOrIsRefusedInImuModeAndTheHealthSaysSo) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
  constexpr int kUpdates = 20;
  {
    transport::LogWriter log(in);
    for (int k = 0; k < 50; ++k) {
      kestrel::imu_t m{};
      m.utime = 1'000'000 + 2'000 * k;
      m.seq = k;
      m.fields = kestrel::imu_t::HAS_ACCEL;
      m.linear_acceleration[2] = 9.81;
      log.write_message(channel::kImu, m.utime, m);
    }
    for (int k = 1; k <= kUpdates; ++k) {  // moving 1 cm per frame along x
      VoUpdate u;
      u.utime = 1'100'000 + 33'333 * k;
      u.reference_utime = u.utime - 33'333;
      u.ok = true;
      u.T_refcam_curcam.translation() << 0.01, 0.0, 0.0;
      u.covariance = Matrix6d::Identity() * 1e-6;
      log.write_message(channel::kVoUpdate, u.utime, test::vo_message(u));
    }
  }
  // The health is announced when it changes and repeated every heartbeat period (1 s): a
  // datagram lost on a loaded machine is made good by the next period's, so each estimator
  // runs until a heartbeat has said what the checks below look for.
  LiveSystem live(dir.path() / "live", {});
  const std::string estimator = kestrel::test::tool("estimator").string();
  live.start("estimator", {estimator, "-q"});
  ASSERT_EQ(live.replay(in, "estimator", dir / "visual.lcmlog", {}, 120.0), 0) << live.output("replay");
  live.wait_for<kestrel::process_status_t>(
      channel::kProcessStatus,
      [](const kestrel::process_status_t& s) {
        return s.name == "estimator" && s.state == kestrel::process_status_t::STATE_RUNNING &&
               s.message.find("visual only") != std::string::npos;
      },
      20.0, "a RUNNING heartbeat of the estimator saying 'visual only'");
  live.stop("estimator");
  const size_t second = live.received();
  live.start("estimator", {estimator, "-q", "--mode", "imu"});
  const int replayed = live.replay(in, "estimator", dir / "imu.lcmlog", {}, 120.0);
  live.wait_for<kestrel::process_status_t>(
      channel::kProcessStatus,
      [](const kestrel::process_status_t& s) {
        return s.name == "estimator" && s.state == kestrel::process_status_t::STATE_DEGRADED &&
               s.message.find("lack the gyro") != std::string::npos;
      },
      20.0, "a DEGRADED heartbeat of the estimator (--mode imu) saying the samples lack the gyro", second);
  live.stop("estimator");
  live.finish();
  ASSERT_EQ(replayed, 0) << live.output("replay");

  const auto states = transport::read_messages<kestrel::state_t>((dir / "visual.lcmlog").string(), channel::kState);
  ASSERT_EQ(states.size(), static_cast<size_t>(kUpdates));
  const LogRunResult offline = run_log(in, EstimatorOptions{});
  EXPECT_EQ(offline.mode, EstimatorMode::kVisualOnly);
  ASSERT_EQ(offline.trajectory.size(), states.size());
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(states[i].filter, kestrel::state_t::FILTER_VISUAL_ONLY);
    EXPECT_EQ(states[i].utime, offline.trajectory.poses()[i].utime);
    EXPECT_NEAR(states[i].T_world_body.position[0], offline.trajectory.poses()[i].T.translation().x(), 1e-12);
  }
  // 20 frames of 1 cm along the camera's x, which the accelerometer's gravity (along the
  // camera's z, body = camera) turns into the world's horizontal plane.
  const auto& p = states.back().T_world_body.position;
  EXPECT_NEAR(std::hypot(p[0], p[1]), 0.01 * kUpdates, 1e-6);
  EXPECT_NEAR(p[2], 0.0, 1e-6);

  EXPECT_TRUE(transport::read_messages<kestrel::state_t>((dir / "imu.lcmlog").string(), channel::kState).empty());
  bool ran_visual = false;
  std::string last_degraded, heard;
  for (const auto& m : live.messages(channel::kProcessStatus)) {
    const auto s = transport::decode_message<kestrel::process_status_t>(m.data.data(), m.data.size(), m.channel);
    if (s.name != "estimator") continue;
    heard += "\n  state " + std::to_string(s.state) + " '" + s.message + "'";
    if (s.state == kestrel::process_status_t::STATE_RUNNING && s.message.find("visual only") != std::string::npos)
      ran_visual = true;
    if (s.state == kestrel::process_status_t::STATE_DEGRADED) last_degraded = s.message;
  }
  EXPECT_TRUE(ran_visual) << "no RUNNING heartbeat saying 'visual only'; heard:" << heard;
  EXPECT_NE(last_degraded.find("lack the gyro"), std::string::npos) << "'" << last_degraded << "'; heard:" << heard;
}

// One accelerometer spike of 500 m/s^2 (beyond a MEMS IMU's 16 g) in a replayed log: the
// process refuses it, its heartbeat says why (DEGRADED, naming the accelerometer), and it
// publishes exactly the states the library gives on the log without the spike.
TEST(EstimatorProcess, AnImuSpikeIsRefusedWithTheHealthSayingWhyAndTheStatesAsWithoutIt) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  kestrel::test::TempDir dir;
  const std::string clean = (dir / "clean.lcmlog").string(), spiked = (dir / "spiked.lcmlog").string();
  const test::SyntheticLog written = test::write_log(clean, 3.0, false);
  {
    transport::LogReader in(clean);
    transport::LogWriter out(spiked);
    size_t imu = 0;
    while (auto event = in.next()) {
      out.write(event->channel, event->timestamp, event->data);
      if (event->channel != channel::kImu || ++imu != 500) continue;
      ImuSample spike = written.imu[499];
      spike.utime += 2500;  // between two samples
      spike.accel = Eigen::Vector3d(500.0, 0.0, kStandardGravity);
      out.write_message(channel::kImu, spike.utime, test::imu_message(spike));
    }
    out.close();
  }
  LiveSystem live(dir.path() / "live", {});
  live.start("estimator", {kestrel::test::tool("estimator").string(), "-q"});
  const int replayed = live.replay(spiked, "estimator", dir / "out.lcmlog", {}, 240.0);
  // The heartbeats after the refusal carry the count: the estimator runs until one has come.
  live.wait_for<kestrel::process_status_t>(
      channel::kProcessStatus,
      [](const kestrel::process_status_t& s) { return s.name == "estimator" && s.messages_rejected >= 1; }, 20.0,
      "a heartbeat of the estimator counting the refused spike");
  live.stop("estimator");
  live.finish();
  ASSERT_EQ(replayed, 0) << live.output("replay");
  const std::string said = live.output("estimator");

  const LogRunResult expected = run_log(clean, EstimatorOptions{});
  const auto states = transport::read_messages<kestrel::state_t>((dir / "out.lcmlog").string(), channel::kState);
  ASSERT_EQ(states.size(), expected.trajectory.size());
  ASSERT_FALSE(states.empty());
  const StampedPose& want = expected.trajectory.poses().back();
  EXPECT_EQ(states.back().utime, want.utime);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(states.back().T_world_body.position[i], want.T.translation()[i], 1e-12);
  // The DEGRADED heartbeat goes out at the refusal; the heartbeats after it carry the count.
  // Heartbeats are UDP: under load lcm-logger may miss the one DEGRADED packet, so the reason is
  // then taken from the process's own log, and the count from a later heartbeat.
  std::string heard;
  bool said_why = false;
  int64_t rejected = 0;
  for (const auto& m : live.messages(channel::kProcessStatus)) {
    const auto s = transport::decode_message<kestrel::process_status_t>(m.data.data(), m.data.size(), m.channel);
    if (s.name != "estimator") continue;
    heard += "\n  state " + std::to_string(s.state) + " '" + s.message + "' rejected " + std::to_string(s.messages_rejected);
    said_why = said_why || (s.state == kestrel::process_status_t::STATE_DEGRADED &&
                            s.message.find("accelerometer") != std::string::npos);
    rejected = std::max<int64_t>(rejected, s.messages_rejected);
  }
  const bool logged_why = said.find("rejected message #1 on IMU") != std::string::npos &&
                          said.find("accelerometer") != std::string::npos;
  EXPECT_TRUE(said_why || (rejected == 1 && logged_why))
      << "no DEGRADED heartbeat naming the accelerometer (nor a count of 1 and the reason in the log); heard:"
      << heard << "\nthe process said:\n" << said;
  EXPECT_LE(rejected, 1) << "only the spike is refused; heard:" << heard;
}

}  // namespace
}  // namespace kestrel::estimator
