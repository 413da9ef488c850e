// A peer process dying in flight: the estimator is killed halfway through the room's
// figure-eight while VO and SLAM run on, and `kestrel launch --restart` starts it again. The
// new filter must not take the walking-pace flight for standing still (its IMU cannot tell),
// publishes once the VO has settled it, and takes the map's world from the SLAM_CORRECTION
// that kestrel-slam sends for its next keyframe on seeing a new estimator (estimator.h,
// slam_adapter.h). Before these, the restarted filter started with velocity zero and SLAM's
// corrections pulled it about by up to 0.6 m for seconds.
//
// Live and timed: the simulator's recording is replayed at its own pace (lock-step replay
// would stall on the dead process), so the figures vary a little from run to run; the bounds
// leave room for that and still fail on a filter left in a world of its own.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/state_t.hpp"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

struct Sample {
  double t = 0.0;  ///< seconds since the first ground truth
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

// The rigid transform that best maps `from` onto `to` (Horn / Umeyama without scale), and the
// RMS of what is left.
double rigid_fit_rms(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) {
    a.col(static_cast<Eigen::Index>(i)) = from[i];
    b.col(static_cast<Eigen::Index>(i)) = to[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(a, b, false);
  const Eigen::Matrix3Xd moved = (T.topLeftCorner<3, 3>() * a).colwise() + T.topRightCorner<3, 1>();
  return std::sqrt((moved - b).colwise().squaredNorm().mean());
}

TEST(System, AnEstimatorKilledInFlightRestartsInTheMapsWorld) {
  if (!test::can_isolate_network()) GTEST_SKIP() << "no network namespace available";
  if (!std::filesystem::exists("/usr/bin/lcm-logger")) GTEST_SKIP() << "lcm-logger is not installed";
  test::TempDir dir;
  const std::string source = (dir / "source.lcmlog").string(), live = (dir / "live.lcmlog").string();
  const auto sim = test::run({test::tool("sim").string(), "--world", "room", "--flight", "figure8", "--duration",
                              "16", "--seed", "1", "--log", source, "-q"},
                             300.0);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;

  // Killed 8 s after the set started (about 7 s into the flight), restarted a second later;
  // by the pid the launcher reports (other tests' estimators may be running beside it).
  const std::string launch_out = test::quoted((dir / "launch.txt").string());
  const std::string script =
      "lcm-logger -q -c 'STATE|GROUND_TRUTH' -f " + test::quoted(live) + " & L=$!; " +
      test::wait_for_lcm_listener_sh() + " && (" + test::quoted(test::tool("launch").string()) +
      " all --only vo,estimator,slam --restart --status-period 0 --log-dir " + test::quoted((dir / "logs").string()) +
      " --source " + test::quoted("replay " + source + " --realtime") + " > " + launch_out +
      " 2>&1 & P=$!; sleep 8; kill -KILL $(sed -n 's/.*started estimator (pid \\([0-9]*\\)).*/\\1/p' " +
      launch_out + " | head -n 1); wait $P); sleep 0.5; kill $L";
  const auto r = test::run_isolated(script, 200.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string launch = test::read_file(dir / "launch.txt");
  const std::string estimator = test::read_file(dir / "logs" / "estimator.log");
  const std::string slam = test::read_file(dir / "logs" / "slam.log");
  ASSERT_NE(launch.find("estimator ("), std::string::npos) << launch;
  ASSERT_NE(launch.find("killed by SIGKILL"), std::string::npos) << launch;
  EXPECT_NE(slam.find("1 estimator restarts"), std::string::npos) << slam;
  EXPECT_NE(estimator.find("1 moved the world onto SLAM's"), std::string::npos) << estimator;

  // STATE against the truth: the dead filter's states, and the new one's from 3 s after its
  // start, under one rigid fit. One world: a few millimetres; two worlds: metres.
  std::map<int64_t, Eigen::Vector3d> truth;
  std::vector<Sample> states;
  int64_t t0 = -1;
  transport::LogReader log(live);
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kGroundTruth) {
      const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
      truth[m.utime] = transport::from_message(m.T_world_frame, "GROUND_TRUTH").translation();
      if (t0 < 0) t0 = m.utime;
    } else if (e->channel == channel::kState && t0 >= 0) {
      const auto m = transport::decode_message<kestrel::state_t>(data.data(), data.size(), "STATE");
      if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) continue;
      states.push_back({1e-6 * static_cast<double>(m.utime - t0), transport::from_message(m.T_world_body, "STATE").translation()});
    }
  }
  ASSERT_GT(states.size(), 100u);
  // The kill: the longest silence on STATE.
  size_t restart = 1;
  for (size_t i = 1; i < states.size(); ++i)
    if (states[i].t - states[i - 1].t > states[restart].t - states[restart - 1].t) restart = i;
  const double gap = states[restart].t - states[restart - 1].t;
  std::printf("STATE silent from %.2f to %.2f s\n", states[restart - 1].t, states[restart].t);
  EXPECT_GT(gap, 1.0) << "the estimator was killed and restarted";
  std::vector<Eigen::Vector3d> est, gt;
  for (size_t i = 0; i < states.size(); ++i) {
    if (i >= restart && states[i].t < states[restart].t + 3.0) continue;
    // The truth nearest in time, within a millisecond (both come at the IMU's 200 Hz).
    const auto it = truth.lower_bound(t0 + std::llround(states[i].t * 1e6) - 1000);
    if (it == truth.end() || std::abs(1e-6 * static_cast<double>(it->first - t0) - states[i].t) > 1e-3) continue;
    est.push_back(states[i].p);
    gt.push_back(it->second);
  }
  size_t after = 0;
  for (size_t i = restart; i < states.size(); ++i) after += states[i].t >= states[restart].t + 3.0;
  ASSERT_GT(after, 200u) << "the restarted filter ran at least a second after its world was set";
  const double rms = rigid_fit_rms(est, gt);
  std::printf("both filters' states under one rigid fit: RMS %.4f m over %zu states (%zu after the restart)\n",
              rms, est.size(), after);
  EXPECT_LT(rms, 0.03);
}

}  // namespace
}  // namespace kestrel
