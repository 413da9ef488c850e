// kestrel-estimator under lock-step replay, in a private network namespace: a synthesised log
// (IMU, VO_UPDATE, a late SLAM_CORRECTION, a duplicate, a NaN sample and a corrupt message)
// replayed twice through one running estimator (RESET between) gives byte-identical STATE
// recordings, one STATE per accepted IMU sample, and the last state equals the library's
// (kestrel estimate's) on the same log. This is the whole process path: LCM decode, the
// message conversions, Node's rejection of bad messages, acks and RESET. An IMU without a gyro
// runs the visual-only estimator, or, in --mode imu, is refused with the heartbeat saying why.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <sstream>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "estimator/log_run.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/state_t.hpp"
#include "test/estimator/synthetic_log.h"
#include "test/support/test_support.h"

namespace kestrel::estimator {
namespace {

TEST(EstimatorProcess, LockStepReplayIsDeterministicResetsAndEqualsTheLibrary) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
  test::write_log(in, 3.0, true);
  const std::string estimator = kestrel::test::tool("estimator").string();
  const std::string replay = kestrel::test::tool("replay").string();
  const std::string script =
      estimator + " --init-yaw 0.3 & P=$!; " + replay + " " + in + " --expect estimator --record " +
      (dir / "a.lcmlog").string() + " || exit 11; " + replay + " " + in +
      " --expect estimator --record " + (dir / "b.lcmlog").string() +
      " || exit 12; kill -INT $P; wait $P";
  const auto r = kestrel::test::run_isolated(script, 240.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
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
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  if (std::system("command -v lcm-logger > /dev/null 2>&1") != 0) KESTREL_SKIP_ENVIRONMENT() << "lcm-logger not found";
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
  const std::string logged = (dir / "heartbeats.lcmlog").string();
  const std::string estimator = kestrel::test::tool("estimator").string();
  const std::string replay = kestrel::test::tool("replay").string();
  const std::string script =
      "lcm-logger -q --lcm-url='" + std::string(transport::kDefaultLcmUrl) + "' -f " + logged +
      " & L=$!; " + kestrel::test::wait_for_lcm_listener_sh() + "; " + estimator + " -q & P=$!; " + replay + " " + in +
      " --expect estimator --record " + (dir / "visual.lcmlog").string() +
      " >/dev/null || exit 11; sleep 1.2; kill -INT $P; wait $P; " + estimator + " -q --mode imu & P=$!; " +
      replay + " " + in + " --expect estimator --record " + (dir / "imu.lcmlog").string() +
      " >/dev/null; R=$?; sleep 1.2; kill -INT $P $L; wait $P; wait $L; exit $R";
  const auto r = kestrel::test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

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
  // The health is announced when it changes and repeated every heartbeat period (1 s): a
  // datagram lost on a loaded machine is made good by the next period's, which the 1.2 s
  // before each stop leaves room for.
  bool ran_visual = false;
  std::string last_degraded, heard;
  for (const auto& s : transport::read_messages<kestrel::process_status_t>(logged, channel::kProcessStatus)) {
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
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    KESTREL_SKIP_ENVIRONMENT() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  if (std::system("command -v lcm-logger > /dev/null 2>&1") != 0) KESTREL_SKIP_ENVIRONMENT() << "lcm-logger not found";
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
  const std::string logged = (dir / "heartbeats.lcmlog").string();
  const std::string script =
      "lcm-logger -q --lcm-url='" + std::string(transport::kDefaultLcmUrl) + "' -f " + logged +
      " & L=$!; " + kestrel::test::wait_for_lcm_listener_sh() + "; " + kestrel::test::tool("estimator").string() +
      " -q & P=$!; " + kestrel::test::tool("replay").string() + " " + spiked + " --expect estimator --record " +
      (dir / "out.lcmlog").string() + " >/dev/null; R=$?; sleep 1.2; kill -INT $P $L; wait $P; wait $L; exit $R";
  const auto r = kestrel::test::run_isolated(script, 240.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

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
  for (const auto& s : transport::read_messages<kestrel::process_status_t>(logged, channel::kProcessStatus)) {
    if (s.name != "estimator") continue;
    heard += "\n  state " + std::to_string(s.state) + " '" + s.message + "' rejected " + std::to_string(s.messages_rejected);
    said_why = said_why || (s.state == kestrel::process_status_t::STATE_DEGRADED &&
                            s.message.find("accelerometer") != std::string::npos);
    rejected = std::max<int64_t>(rejected, s.messages_rejected);
  }
  const bool logged_why = r.err.find("rejected message #1 on IMU") != std::string::npos &&
                          r.err.find("accelerometer") != std::string::npos;
  EXPECT_TRUE(said_why || (rejected == 1 && logged_why))
      << "no DEGRADED heartbeat naming the accelerometer (nor a count of 1 and the reason in the log); heard:"
      << heard << "\nthe process said:\n" << r.err;
  EXPECT_LE(rejected, 1) << "only the spike is refused; heard:" << heard;
}

}  // namespace
}  // namespace kestrel::estimator
