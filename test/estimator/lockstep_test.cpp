// kestrel-estimator under lock-step replay, in a private network namespace: a synthesised log
// (IMU, VO_UPDATE, a late SLAM_CORRECTION, a duplicate, a NaN sample and a corrupt message)
// replayed twice through one running estimator (RESET between) gives byte-identical STATE
// recordings, one STATE per accepted IMU sample, and the last state equals the library's
// (kestrel estimate's) on the same log. This is the whole process path: LCM decode, the
// message conversions, Node's rejection of bad messages, acks and RESET. An IMU without a gyro
// is refused sample by sample, and the heartbeat says why.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
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
  if (!kestrel::test::can_isolate_network()) GTEST_SKIP() << "no network namespace available";
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    GTEST_SKIP() << kestrel::test::tool("replay") << " is not built (tools/replay)";
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
  const auto r = kestrel::test::run({kestrel::test::tool("isolated").string(), "--", "sh", "-c", script}, 240.0);
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

// An IMU without a gyro (a TUM recording: the Kinect's accelerometer only): every sample is
// refused, no STATE is published, and the heartbeat says why instead of "initialising".
TEST(EstimatorProcess, AnImuWithoutAGyroIsRefusedAndTheHealthSaysSo) {
  if (!kestrel::test::can_isolate_network()) GTEST_SKIP() << "no network namespace available";
  if (!std::filesystem::exists(kestrel::test::tool("replay")))
    GTEST_SKIP() << kestrel::test::tool("replay") << " is not built (tools/replay)";
  if (std::system("command -v lcm-logger > /dev/null 2>&1") != 0) GTEST_SKIP() << "lcm-logger not found";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
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
  }
  const std::string logged = (dir / "heartbeats.lcmlog").string();
  const std::string script =
      "lcm-logger -q --lcm-url='" + std::string(transport::kDefaultLcmUrl) + "' -f " + logged +
      " & L=$!; sleep 0.5; " + kestrel::test::tool("estimator").string() + " -q & P=$!; " +
      kestrel::test::tool("replay").string() + " " + in + " --expect estimator --record " +
      (dir / "out.lcmlog").string() + " >/dev/null; R=$?; sleep 0.3; kill -INT $P $L; wait $P; wait $L; exit $R";
  const auto r = kestrel::test::run({kestrel::test::tool("isolated").string(), "--", "sh", "-c", script}, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(transport::read_messages<kestrel::state_t>((dir / "out.lcmlog").string(), channel::kState).empty());
  std::string last_health;
  for (const auto& s : transport::read_messages<kestrel::process_status_t>(logged, channel::kProcessStatus))
    if (s.name == "estimator" && s.state == kestrel::process_status_t::STATE_DEGRADED) last_health = s.message;
  EXPECT_NE(last_health.find("lack the gyro"), std::string::npos) << "'" << last_health << "'";
}

}  // namespace
}  // namespace kestrel::estimator
