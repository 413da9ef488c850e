// A peer process dying in flight. The estimator is killed halfway through the room's
// figure-eight while VO and SLAM run on, and `kestrel launch --restart` starts it again. The
// new filter must not take the walking-pace flight for standing still (its IMU cannot tell),
// publishes once the VO has settled it, and takes the map's world from the SLAM_CORRECTION
// that kestrel-slam sends for its next frame on seeing a new estimator (estimator.h,
// slam_adapter.h). Before these, the restarted filter started with velocity zero and SLAM's
// corrections pulled it about by up to 0.6 m for seconds. Then SLAM is killed the same way
// while the estimator and the mapper run on: the new SLAM session's map lies in the same world
// and the mapper keeps both sessions' keyframes (slam/slam_messages.h). Then the mapper is
// killed: it comes back with its map from its journal (mapper/keyframe_journal.h). Then the
// VO is killed: the estimator and SLAM carry on across its silence. Last, the planner is killed
// while the vehicle hovers, and a goal asked for meanwhile is still flown; and the estimator,
// while the vehicle hovers where a keyframe never comes.
//
// Live and timed: the simulator's recording is replayed at its own pace (lock-step replay
// would stall on the dead process), so the figures vary a little from run to run; the bounds
// leave room for that and still fail on a filter left in a world of its own.
//
// The processes run under a LiveSystem (test/support/live_system.h): the test hears their
// messages itself, kills a process when the flight has reached the moment (GROUND_TRUTH's
// time, a goto's second request, the new filter's first state), by the pid its heartbeat
// gives, and never sleeps.

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/support/live_system.h"
#include "test/support/test_support.h"
#include "metrics/alignment.h"

namespace kestrel {
namespace {

struct Sample {
  double t = 0.0;  ///< seconds since the first ground truth
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

// The rigid transform that best maps `from` onto `to` (kestrel eval's ATE alignment), and the
// RMS of what is left.
double rigid_fit_rms(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) {
    a.col(static_cast<Eigen::Index>(i)) = from[i];
    b.col(static_cast<Eigen::Index>(i)) = to[i];
  }
  const Eigen::Matrix3Xd moved = metrics::align_positions(a, b).T_gt_est * a;
  return std::sqrt((moved - b).colwise().squaredNorm().mean());
}

// The true camera position at `utime`, linearly between the truth's samples around it.
std::optional<Eigen::Vector3d> true_camera_position(const std::map<int64_t, Eigen::Isometry3d>& truth, int64_t utime,
                                                    const Eigen::Isometry3d& T_body_camera) {
  const auto hi = truth.lower_bound(utime);
  if (hi == truth.end() || hi == truth.begin()) return std::nullopt;
  const auto lo = std::prev(hi);
  const double s = static_cast<double>(utime - lo->first) / static_cast<double>(hi->first - lo->first);
  return (1.0 - s) * (lo->second * T_body_camera).translation() + s * (hi->second * T_body_camera).translation();
}

// Flies the room's figure-eight (16 s, replayed at its own pace) through `processes` under
// `kestrel launch --restart` and kills `victim` once the flight's ground truth has reached 7 s
// (by the pid of the victim's heartbeat, since other tests' processes may run beside it).
// `channels` are recorded in dir/live.lcmlog; the launcher's output is dir/launch.log, the
// processes' logs are in dir/logs. With `down`, the flight's time (GROUND_TRUTH utime) at
// the kill and when the restarted victim's first heartbeat came: the window in which it heard
// nothing, which depends on the machine's load.
struct DownWindow {
  int64_t from_utime = 0;
  int64_t to_utime = 0;
};
void fly_and_kill(const test::TempDir& dir, const std::string& processes, const std::string& victim,
                  const std::vector<std::string>& channels, DownWindow* down = nullptr) {
  const std::string source = (dir / "source.lcmlog").string();
  const auto sim = test::run({test::tool("sim").string(), "--world", "room", "--flight", "figure8", "--duration",
                              "16", "--seed", "1", "--log", source, "-q"},
                             300.0);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const auto flight = transport::read_messages<kestrel::ground_truth_t>(source, channel::kGroundTruth);
  ASSERT_FALSE(flight.empty());
  const int64_t kill_at = flight.front().utime + 7'000'000;
  std::vector<std::string> heard = channels;
  if (std::find(heard.begin(), heard.end(), channel::kGroundTruth) == heard.end())
    heard.push_back(channel::kGroundTruth);
  {
    test::LiveSystem live(dir.path(), {heard, dir / "live.lcmlog", channels});
    live.start("launch", {test::tool("launch").string(), "all", "--only", processes, "--restart", "--status-period",
                          "0", "--log-dir", (dir / "logs").string(), "--source", "replay " + source + " --realtime"});
    const pid_t pid = live.wait_heartbeat(victim, 60.0);
    ASSERT_NE(pid, 0) << live.output("launch");
    ASSERT_TRUE(live.wait_for<kestrel::ground_truth_t>(
        channel::kGroundTruth, [&](const kestrel::ground_truth_t& m) { return m.utime >= kill_at; }, 60.0,
        "the flight's 7th second"))
        << live.output("launch");
    const size_t killed_at = live.received();
    test::LiveSystem::kill_pid(pid, SIGKILL);
    if (down) {
      down->from_utime = kill_at;
      const auto back = live.wait_for<kestrel::process_status_t>(
          channel::kProcessStatus,
          [&](const kestrel::process_status_t& s) { return s.name == victim && s.pid != pid; }, 60.0,
          "the restarted " + victim + "'s heartbeat", killed_at);
      ASSERT_TRUE(back.has_value()) << live.output("launch");
      const auto now = live.wait_for<kestrel::ground_truth_t>(
          channel::kGroundTruth, [](const kestrel::ground_truth_t&) { return true; }, 30.0,
          "the flight after the restart", live.received());
      ASSERT_TRUE(now.has_value());
      down->to_utime = now->utime;
    }
    const int status = live.exit_status("launch", 200.0);
    live.finish();
    ASSERT_EQ(status, 0) << live.output("launch");
  }
  const std::string launch = test::read_file(dir / "launch.log");
  ASSERT_NE(launch.find("started " + victim + " ("), std::string::npos) << launch;
  ASSERT_NE(launch.find("killed by SIGKILL"), std::string::npos) << launch;
}

TEST(System, AnEstimatorKilledInFlightRestartsInTheMapsWorld) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  ASSERT_NO_FATAL_FAILURE(fly_and_kill(dir, "vo,estimator,slam", "estimator", {"STATE", "GROUND_TRUTH"}));
  const std::string live = (dir / "live.lcmlog").string();
  const std::string estimator = test::read_file(dir / "logs" / "estimator.log");
  const std::string slam = test::read_file(dir / "logs" / "slam.log");
  EXPECT_NE(slam.find("1 estimator restarts"), std::string::npos) << slam;
  EXPECT_NE(estimator.find("1 moved the world onto SLAM's"), std::string::npos) << estimator;

  // STATE against the truth: the dead filter's usable states and every one of the new
  // filter's (OK or DEGRADED: it publishes them once SLAM's correction has set its world,
  // --await-world, as kestrel launch runs a restarted estimator), under one rigid fit. One
  // world: a few millimetres; two worlds: metres.
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
    // The truth nearest in time, within a millisecond (both come at the IMU's 200 Hz).
    const auto it = truth.lower_bound(t0 + std::llround(states[i].t * 1e6) - 1000);
    if (it == truth.end() || std::abs(1e-6 * static_cast<double>(it->first - t0) - states[i].t) > 1e-3) continue;
    est.push_back(states[i].p);
    gt.push_back(it->second);
  }
  const size_t after = states.size() - restart;
  ASSERT_GT(after, 200u) << "the restarted filter ran at least a second";
  const double rms = rigid_fit_rms(est, gt);
  std::printf("both filters' states under one rigid fit: RMS %.4f m over %zu states (%zu after the restart)\n",
              rms, est.size(), after);
  EXPECT_LT(rms, 0.03);
}

TEST(System, ASlamKilledInFlightStartsANewSessionInTheSameWorldAndTheMapKeepsBoth) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  ASSERT_NO_FATAL_FAILURE(fly_and_kill(dir, "vo,estimator,slam,mapper", "slam", {"GROUND_TRUTH", "SLAM_GRAPH", "VO_UPDATE"}));
  const std::string live = (dir / "live.lcmlog").string();
  const std::string mapper = test::read_file(dir / "logs" / "mapper.log");

  std::map<int64_t, Eigen::Isometry3d> truth;
  std::vector<kestrel::slam_graph_t> graphs;
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  transport::LogReader log(live);
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kGroundTruth) {
      const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
      truth[m.utime] = transport::from_message(m.T_world_frame, "GROUND_TRUTH");
    } else if (e->channel == channel::kSlamGraph) {
      graphs.push_back(transport::decode_message<kestrel::slam_graph_t>(data.data(), data.size(), "SLAM_GRAPH"));
    } else if (e->channel == channel::kVoUpdate) {
      const auto m = transport::decode_message<kestrel::vo_update_t>(data.data(), data.size(), "VO_UPDATE");
      T_body_camera = transport::from_message(m.T_body_camera, "VO_UPDATE");
    }
  }
  ASSERT_FALSE(graphs.empty());
  // The sessions: graphs holding the very first keyframe are the first SLAM's.
  const int64_t first_id = graphs.front().keyframes.front().id;
  const auto of_first = [&](const kestrel::slam_graph_t& g) {
    return std::any_of(g.keyframes.begin(), g.keyframes.end(), [&](const auto& k) { return k.id == first_id; });
  };
  const kestrel::slam_graph_t* before = nullptr;
  const kestrel::slam_graph_t* after = nullptr;
  for (size_t i = 0; i < graphs.size(); ++i) {
    if (i > 0) {
      EXPECT_GE(graphs[i].revision, graphs[i - 1].revision) << "graph " << i << " went back in revision";
    }
    (of_first(graphs[i]) ? before : after) = &graphs[i];
  }
  ASSERT_NE(before, nullptr);
  ASSERT_NE(after, nullptr) << "no graph from the restarted SLAM";
  std::set<int64_t> old_ids;
  for (const auto& k : before->keyframes) old_ids.insert(k.id);
  for (const auto& k : after->keyframes) EXPECT_EQ(old_ids.count(k.id), 0u) << "id " << k.id << " reused";
  std::printf("first session %d keyframes (revision %lld), second %d (revision %lld)\n", before->num_keyframes,
              static_cast<long long>(before->revision), after->num_keyframes, static_cast<long long>(after->revision));

  // Both sessions' keyframes against the true camera positions under one rigid fit: one world,
  // centimetres; a new session in a world of its own would be off by where the vehicle was.
  std::vector<Eigen::Vector3d> est, gt;
  for (const auto* g : {before, after}) {
    for (const auto& k : g->keyframes) {
      const auto p = true_camera_position(truth, k.utime, T_body_camera);
      if (!p) continue;
      gt.push_back(*p);
      est.push_back(transport::from_message(k.T_world_camera, "SLAM_GRAPH").translation());
    }
  }
  ASSERT_GT(est.size(), 10u);
  const double rms = rigid_fit_rms(est, gt);
  std::printf("both sessions' keyframes under one rigid fit: RMS %.4f m over %zu keyframes\n", rms, est.size());
  EXPECT_LT(rms, 0.05);

  // The mapper refused nothing and put the second session's keyframes into the map too.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(mapper, m, std::regex(R"((\d+) frames \((\d+) inserted.* (\d+) rejected)"))) << mapper;
  const int inserted = std::stoi(m[2]), rejected = std::stoi(m[3]);
  std::printf("mapper: %d keyframes inserted, %d messages rejected\n", inserted, rejected);
  EXPECT_EQ(rejected, 0) << mapper;
  EXPECT_GT(inserted, before->num_keyframes + after->num_keyframes / 2) << mapper;
}

// The mapper killed in flight: restarted on its journal (the launch's {run_dir}), it publishes
// the map it had at once and carries on adding SLAM's keyframes; only those SLAM made while it
// was down are missing. Without the journal it would start from nothing.
TEST(System, AMapperKilledInFlightComesBackWithItsMapFromTheJournal) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  DownWindow down;
  ASSERT_NO_FATAL_FAILURE(fly_and_kill(dir, "vo,estimator,slam,mapper", "mapper", {"SLAM_GRAPH", "MAP_OCTOMAP"}, &down));
  const std::string mapper = test::read_file(dir / "logs" / "mapper.log");

  kestrel::slam_graph_t last_graph;
  std::vector<kestrel::octomap_t> before, after;  // maps of the killed mapper and of its successor
  transport::LogReader log((dir / "live.lcmlog").string());
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kSlamGraph) {
      last_graph = transport::decode_message<kestrel::slam_graph_t>(data.data(), data.size(), "SLAM_GRAPH");
    } else if (e->channel == channel::kMapOctomap) {
      auto m = transport::decode_message<kestrel::octomap_t>(data.data(), data.size(), "MAP_OCTOMAP");
      // A new process counts its revisions from 1 again (a map sent again keeps its revision).
      if (!after.empty() || (!before.empty() && m.revision < before.back().revision)) {
        after.push_back(std::move(m));
      } else {
        before.push_back(std::move(m));
      }
    }
  }
  ASSERT_FALSE(before.empty());
  ASSERT_FALSE(after.empty()) << "no map from the restarted mapper\n" << mapper;

  std::smatch m;
  ASSERT_TRUE(std::regex_search(mapper, m, std::regex(R"(journal \S+: ([1-9]\d*) keyframes restored)"))) << mapper;
  const int restored = std::stoi(m[1]);
  ASSERT_TRUE(std::regex_search(mapper, m, std::regex(R"((\d+) frames \((\d+) inserted.* (\d+) rejected)"))) << mapper;
  const int inserted = std::stoi(m[2]), rejected = std::stoi(m[3]);
  std::printf("mapper: %d keyframes restored, %d inserted after the restart, SLAM's final graph %d; "
              "last map before the kill %d bytes, first after %d bytes, last %d bytes\n",
              restored, inserted, last_graph.num_keyframes, before.back().size, after.front().size,
              after.back().size);
  EXPECT_EQ(rejected, 0) << mapper;
  EXPECT_GE(restored, 6) << "the keyframes of the first 7 s";
  // Missing may be the keyframes whose frames came while no mapper listened: from a second
  // before the kill (SLAM makes a keyframe a little after its frame) to the new mapper's first
  // heartbeat. That window is 1-2 s on an idle machine and longer under load.
  const int64_t missable = std::count_if(last_graph.keyframes.begin(), last_graph.keyframes.end(), [&](const auto& k) {
    return k.utime >= down.from_utime - 1'000'000 && k.utime <= down.to_utime;
  });
  std::printf("mapper down from %.2f s to %.2f s after SLAM's first keyframe: %lld keyframes made meanwhile\n",
              1e-6 * static_cast<double>(down.from_utime - last_graph.keyframes.front().utime),
              1e-6 * static_cast<double>(down.to_utime - last_graph.keyframes.front().utime),
              static_cast<long long>(missable));
  EXPECT_GE(restored + inserted, last_graph.num_keyframes - missable)
      << "only those made while the mapper was down are missing";
  // The first map of the restarted mapper is the map it had, published at once.
  EXPECT_GE(after.front().size, 0.9 * before.back().size);
  EXPECT_GE(after.back().size, after.front().size);
}

// The VO killed in flight: the estimator carries the state on the IMU alone (DEGRADED) until
// the new VO's first motion, and SLAM bridges the new VO's chain to the old one by the
// estimator's motion over the gap (slam_adapter.h), so the state and the graph stay in one
// world. (On this figure-eight the loop closures after the restart would also pull an
// unbridged segment back; the bridge count says which one did it.)
TEST(System, AVoKilledInFlightLeavesTheStateAndTheGraphInOneWorld) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  ASSERT_NO_FATAL_FAILURE(fly_and_kill(dir, "vo,estimator,slam", "vo", {"STATE", "GROUND_TRUTH", "SLAM_GRAPH", "VO_UPDATE"}));
  const std::string slam = test::read_file(dir / "logs" / "slam.log");
  EXPECT_NE(slam.find("1 VO restarts bridged by the estimator"), std::string::npos) << slam;

  std::map<int64_t, Eigen::Isometry3d> truth;
  struct State {
    int64_t utime;
    Eigen::Vector3d p;
    int status;
  };
  std::vector<State> states;
  std::vector<int64_t> vo_utimes;
  kestrel::slam_graph_t last_graph;
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  transport::LogReader log((dir / "live.lcmlog").string());
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kGroundTruth) {
      const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
      truth[m.utime] = transport::from_message(m.T_world_frame, "GROUND_TRUTH");
    } else if (e->channel == channel::kState) {
      const auto m = transport::decode_message<kestrel::state_t>(data.data(), data.size(), "STATE");
      if (m.status == kestrel::state_t::STATUS_INITIALIZING) continue;
      states.push_back({m.utime, transport::from_message(m.T_world_body, "STATE").translation(), m.status});
    } else if (e->channel == channel::kSlamGraph) {
      last_graph = transport::decode_message<kestrel::slam_graph_t>(data.data(), data.size(), "SLAM_GRAPH");
    } else if (e->channel == channel::kVoUpdate) {
      const auto m = transport::decode_message<kestrel::vo_update_t>(data.data(), data.size(), "VO_UPDATE");
      T_body_camera = transport::from_message(m.T_body_camera, "VO_UPDATE");
      vo_utimes.push_back(m.utime);
    }
  }
  ASSERT_FALSE(truth.empty());
  ASSERT_GT(vo_utimes.size(), 100u);
  ASSERT_GT(states.size(), 1000u);
  const int64_t t0 = truth.begin()->first;
  const auto seconds = [&](int64_t utime) { return 1e-6 * static_cast<double>(utime - t0); };
  // The kill: the longest silence on VO_UPDATE.
  size_t gap = 1;
  for (size_t i = 1; i < vo_utimes.size(); ++i)
    if (vo_utimes[i] - vo_utimes[i - 1] > vo_utimes[gap] - vo_utimes[gap - 1]) gap = i;
  const int64_t silent_from = vo_utimes[gap - 1], silent_to = vo_utimes[gap];
  std::printf("VO silent from %.2f to %.2f s\n", seconds(silent_from), seconds(silent_to));
  ASSERT_GT(seconds(silent_to) - seconds(silent_from), 1.0) << "the VO was killed and restarted";

  // STATE went on through the silence, on the IMU alone, and came back to OK after it.
  int degraded = 0, ok_after = 0;
  double longest_state_gap = 0.0;
  for (size_t i = 0; i < states.size(); ++i) {
    if (i > 0) longest_state_gap = std::max(longest_state_gap, seconds(states[i].utime) - seconds(states[i - 1].utime));
    degraded += states[i].utime > silent_from && states[i].utime < silent_to &&
                states[i].status == kestrel::state_t::STATUS_DEGRADED;
    ok_after += states[i].utime > silent_to + 1'000'000 && states[i].status == kestrel::state_t::STATUS_OK;
  }
  std::printf("STATE: longest silence %.3f s, %d DEGRADED while the VO was down, %d OK from 1 s after\n",
              longest_state_gap, degraded, ok_after);
  EXPECT_LT(longest_state_gap, 0.1);
  EXPECT_GT(degraded, 50) << "predicting on the IMU alone is DEGRADED";
  EXPECT_GT(ok_after, 1000);

  // The states against the truth under one rigid fit: the IMU-only stretch drifts centimetres,
  // and the new VO's motions carry on from where the filter is.
  std::vector<Eigen::Vector3d> est, gt;
  for (const State& s : states) {
    const auto it = truth.find(s.utime);  // both at the IMU's times
    if (it == truth.end()) continue;
    est.push_back(s.p);
    gt.push_back(it->second.translation());
  }
  ASSERT_GT(est.size(), 1000u);
  Eigen::Matrix3Xd a(3, est.size()), b(3, gt.size());
  for (size_t i = 0; i < est.size(); ++i) {
    a.col(static_cast<Eigen::Index>(i)) = est[i];
    b.col(static_cast<Eigen::Index>(i)) = gt[i];
  }
  const Eigen::Matrix3Xd errors = metrics::align_positions(a, b).T_gt_est * a - b;
  const double rms = std::sqrt(errors.colwise().squaredNorm().mean());
  const double worst = errors.colwise().norm().maxCoeff();
  std::printf("states under one rigid fit: RMS %.4f m, worst %.4f m over %zu states\n", rms, worst, est.size());
  EXPECT_LT(rms, 0.02);
  EXPECT_LT(worst, 0.08);

  // SLAM's graph holds keyframes from both sides of the silence, in one world.
  std::vector<Eigen::Vector3d> kest, kgt;
  int before = 0, after = 0;
  for (const auto& k : last_graph.keyframes) {
    before += k.utime < silent_from;
    after += k.utime > silent_to;
    const auto p = true_camera_position(truth, k.utime, T_body_camera);
    if (!p) continue;
    kgt.push_back(*p);
    kest.push_back(transport::from_message(k.T_world_camera, "SLAM_GRAPH").translation());
  }
  std::printf("SLAM's final graph: %d keyframes before the silence, %d after; %zu against the truth\n", before,
              after, kest.size());
  EXPECT_GE(before, 6);
  EXPECT_GE(after, 6);
  ASSERT_GE(kest.size(), static_cast<size_t>(before + after));
  const double keyframe_rms = rigid_fit_rms(kest, kgt);
  std::printf("keyframes under one rigid fit: RMS %.4f m\n", keyframe_rms);
  EXPECT_LT(keyframe_rms, 0.03);
}

// Ends a lock-step flight ("sim", run with a --duration to spare) once `settle_s` of the
// flight's time have passed after the last GROUND_TRUTH heard (which the LiveSystem must hear):
// the vehicle has had time to settle where it was sent, and the rest of the --duration would
// only hover. The simulator stops on SIGINT as at its end, with its summary; its exit code is
// then kExitInterrupted, returned here; -1, with a test failure, if no GROUND_TRUTH comes that
// late (the flight ended first).
int end_flight(test::LiveSystem& live, double settle_s) {
  const auto truths = live.messages(channel::kGroundTruth);
  if (truths.empty()) return -1;
  const int64_t until = transport::decode_message<kestrel::ground_truth_t>(
                            truths.back().data.data(), truths.back().data.size(), "GROUND_TRUTH").utime +
                        std::llround(settle_s * 1e6);
  if (!live.wait_for<kestrel::ground_truth_t>(
          channel::kGroundTruth, [&](const kestrel::ground_truth_t& m) { return m.utime >= until; }, 60.0,
          "the flight's time after the last goal"))
    return -1;
  live.kill("sim", SIGINT);
  return live.exit_status("sim", 30.0);
}

// The planner killed while the vehicle hovers, and `kestrel goto` asking while it is down (the
// closed-loop room of autonomy_test.cpp). The request nobody heard is sent again, and the new
// planner gets the map although a hover makes no new keyframes: the mapper sends its last map
// again each second of frames. Before, goto waited out its timeout for an answer, and the new
// planner answered "no map yet" for as long as the vehicle stood still, which was for ever.
TEST(System, APlannerKilledWhileTheVehicleHoversPlansAgainOnceRestarted) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  const auto bin = [](const char* name) { return test::tool(name).string(); };
  const std::vector<std::string> planner = {bin("planner"), "--height", "1.3", "--sensor", "kinect"};
  int sim_status = -1, goto_status = -1;
  {
    test::LiveSystem live(dir.path(), {{channel::kPlan, channel::kMapOctomap, channel::kGroundTruth, channel::kPlanRequest,
                                        channel::kState},
                                       dir / "flight.lcmlog",
                                       {channel::kPlan, channel::kMapOctomap, channel::kGroundTruth, channel::kState}});
    live.start("vo", {bin("vo"), "-q"});
    live.start("estimator", {bin("estimator"), "-q", "--init-position", "8,3.5,1.3"});
    live.start("slam", {bin("slam"), "-q"});
    live.start("mapper", {bin("mapper"), "--publish-period", "1"});
    live.start("planner1", planner);
    live.start("follow", {bin("follow")});
    // The simulator's lock-step session takes in the processes that are there: all of them.
    for (const char* name : {"vo", "estimator", "slam", "mapper", "planner", "follow"})
      ASSERT_NE(live.wait_heartbeat(name), 0) << name;
    live.start("sim", {bin("sim"), "-q", "--world", "room", "--flight", "vehicle", "--lockstep", "5", "--duration", "30"});
    // The planner dies while the vehicle hovers at its take-off, once the mapper has sent a map.
    ASSERT_TRUE(live.wait_for<kestrel::octomap_t>(channel::kMapOctomap, [](const kestrel::octomap_t&) { return true; },
                                                  60.0, "the mapper's first map"))
        << live.output("sim");
    live.kill("planner1", SIGKILL);
    live.start("goto", {bin("goto"), "--goal", "9.5", "3.5", "1.3", "0", "--wait", "--arrive-radius", "0.1",
                        "--timeout", "90"});
    // The new planner once goto has given up on the first request and sent it again (its resend
    // is timed on STATE's sensor time, which under lock-step stands still while the dead planner
    // is waited for).
    int requests = 0;
    ASSERT_TRUE(live.wait_for<kestrel::plan_request_t>(
        channel::kPlanRequest, [&](const kestrel::plan_request_t&) { return ++requests == 2; }, 60.0,
        "goto's second request"))
        << live.output("goto");
    live.start("planner2", planner);
    // goto arrives within the flight (30 s of it, lock-step), or it never will: the flight
    // ends 2 s after it has, or at its end.
    std::optional<int> went;
    while (!(went = live.wait_exit("goto", 0.5)) && !live.wait_exit("sim", 0.0)) {
    }
    sim_status = went ? end_flight(live, 2.0) : live.exit_status("sim", 1.0);
    if (!went) went = live.wait_exit("goto", 1.0);
    goto_status = went ? *went : live.stop("goto", SIGTERM);
    live.stop_all();
    live.finish();
  }
  const std::string go = test::read_file(dir / "goto.log");
  // The simulator is stopped once goto has arrived (130), or ends at its --duration (0).
  EXPECT_TRUE((sim_status == 130 || sim_status == 0) && goto_status == 0)
      << "sim " << sim_status << ", goto " << goto_status << "; goto said:\n" << go << "\nplanner said:\n" << test::read_file(dir / "planner2.log")
      << "\nsim said:\n" << test::read_file(dir / "sim.log");
  EXPECT_NE(go.find("no answer after"), std::string::npos) << "the first request went to the dead planner\n" << go;
  EXPECT_NE(go.find("arrived"), std::string::npos) << go;

  int ok_plans = 0;
  std::optional<Eigen::Vector3d> truth;  // the last
  std::map<int64_t, Eigen::Vector3d> truth_at;
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> last_matched;  // the last STATE, the truth then
  std::map<std::pair<int64_t, int64_t>, int> sent;  // MAP_OCTOMAP (revision, utime): times sent
  transport::LogReader log((dir / "flight.lcmlog").string());
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kState) {
      const auto m = transport::decode_message<kestrel::state_t>(data.data(), data.size(), "STATE");
      if (const auto t = truth_at.find(m.utime); t != truth_at.end())
        last_matched = {transport::from_message(m.T_world_body, "STATE").translation(), t->second};
    } else if (e->channel == channel::kPlan) {
      ok_plans += transport::decode_message<kestrel::plan_t>(data.data(), data.size(), "PLAN").status ==
                  kestrel::plan_t::STATUS_OK;
    } else if (e->channel == channel::kMapOctomap) {
      const auto m = transport::decode_message<kestrel::octomap_t>(data.data(), data.size(), "MAP_OCTOMAP");
      ++sent[{m.revision, m.utime}];
    } else if (e->channel == channel::kGroundTruth) {
      const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
      truth = transport::from_message(m.T_world_frame, "GROUND_TRUTH").translation();
      truth_at[m.utime] = *truth;
    }
  }
  int repeats = 0;
  for (const auto& [key, n] : sent) repeats += n - 1;
  ASSERT_TRUE(truth && last_matched);
  const auto& [state_end, truth_end] = *last_matched;
  const double state_error_m = (state_end - truth_end).norm();
  std::printf("%d plans, %zu maps, %d sent again; the vehicle ended at (%.3f, %.3f, %.3f), its STATE %.3f m from it\n",
              ok_plans, sent.size(), repeats, truth->x(), truth->y(), truth->z(), state_error_m);
  EXPECT_GE(ok_plans, 1);
  EXPECT_GE(repeats, 1) << "the hover's map went out again\n" << test::read_file(dir / "mapper.log");
  // goto's arrival is judged on STATE (--arrive-radius 0.1), and the follower holds the goal
  // for the 2 s after it: in 6 runs here the vehicle really ended 2-7 cm from the goal, its
  // STATE 1-2 cm from the truth. Once (in CI, and 1 in 6 here, STATE not recorded then) it
  // ended 15 cm off, having arrived at 9.9 cm by its state: these bounds tell the two apart.
  const Eigen::Vector3d goal(9.5, 3.5, 1.3);
  EXPECT_LT(state_error_m, 0.06) << "the STATE at the end, against the truth";
  EXPECT_LT((truth_end - goal).norm(), 0.12) << "where the vehicle really ended (its STATE " << (state_end - goal).norm()
                                             << " m from the goal)";
}


// The estimator killed while the vehicle hovers at a goal 1.5 m from its take-off, then a new
// goal (the closed-loop room of autonomy_test.cpp). The new estimator starts in a world of its
// own (at the take-off pose its options give) and a hover makes no keyframe, so SLAM sends the
// map's world for the next frame rather than the next keyframe (slam_adapter.h), and until it
// comes the new filter's STATE is INITIALIZING (--await-world, as kestrel launch runs a
// restarted estimator: processes.yaml's restart_args), so nobody flies on it. The first
// estimator defines the world, as the launch's first one does: it awaits nothing. Before, the
// new filter stayed 1.5 m off for as long as the vehicle hovered, and the next goal was
// planned and flown from where the vehicle was not.
TEST(System, AnEstimatorKilledWhileTheVehicleHoversTakesTheMapsWorldAtOnce) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  const auto bin = [](const char* name) { return test::tool(name).string(); };
  // As launched: the first with the command, the restarted one with its restart_args too.
  const std::vector<std::string> estimator = {bin("estimator"), "--init-position", "8,3.5,1.3"};
  std::vector<std::string> restarted_estimator = estimator;
  restarted_estimator.insert(restarted_estimator.end(), {"--await-world", "1"});
  const auto go = [&](const char* x, const char* y) {
    return std::vector<std::string>{bin("goto"), "--wait", "--arrive-radius", "0.1", "--timeout", "60", "--goal",
                                    x, y, "1.3", "0"};
  };
  int sim_status = -1, goto1 = -1, goto2 = -1;
  {
    test::LiveSystem live(dir.path(), {{channel::kState, channel::kGroundTruth, channel::kMapOctomap},
                                       dir / "flight.lcmlog",
                                       {channel::kState, channel::kGroundTruth}});
    live.start("vo", {bin("vo"), "-q"});
    live.start("estimator1", estimator);
    live.start("slam", {bin("slam")});
    live.start("mapper", {bin("mapper"), "-q", "--publish-period", "1"});
    live.start("planner", {bin("planner"), "-q", "--height", "1.3", "--sensor", "kinect"});
    live.start("follow", {bin("follow"), "-q"});
    // The simulator's lock-step session takes in the processes that are there: all of them.
    for (const char* name : {"vo", "estimator", "slam", "mapper", "planner", "follow"})
      ASSERT_NE(live.wait_heartbeat(name), 0) << name;
    live.start("sim", {bin("sim"), "--world", "room", "--flight", "vehicle", "--lockstep", "5", "--duration", "60"});
    // The first goal once the planner has a map to plan on (the mapper's first).
    ASSERT_TRUE(live.wait_for<kestrel::octomap_t>(channel::kMapOctomap, [](const kestrel::octomap_t&) { return true; },
                                                  60.0, "the mapper's first map"))
        << live.output("sim");
    goto1 = live.run("goto1", go("9.5", "3.5"), 120.0);
    // Two seconds of the flight's time hovering at the goal, then the estimator dies.
    const auto truths = live.messages(channel::kGroundTruth);
    ASSERT_FALSE(truths.empty()) << live.output("sim");
    const int64_t arrived = transport::decode_message<kestrel::ground_truth_t>(
                                truths.back().data.data(), truths.back().data.size(), "GROUND_TRUTH").utime;
    ASSERT_TRUE(live.wait_for<kestrel::ground_truth_t>(
        channel::kGroundTruth, [&](const kestrel::ground_truth_t& m) { return m.utime >= arrived + 2'000'000; }, 60.0,
        "two seconds of hover at the goal"))
        << live.output("sim");
    live.kill("estimator1", SIGKILL);
    live.exit_status("estimator1", 10.0);
    const pid_t restarted = live.start("estimator2", restarted_estimator);
    // The second goal once the new filter is in the map's world: its first usable STATE after
    // its first heartbeat (the dead filter's last states came before it).
    ASSERT_TRUE(live.wait_for<kestrel::process_status_t>(
        channel::kProcessStatus,
        [&](const kestrel::process_status_t& m) { return m.name == "estimator" && m.pid == restarted; }, 20.0,
        "the new estimator's heartbeat"));
    ASSERT_TRUE(live.wait_for<kestrel::state_t>(
        channel::kState,
        [](const kestrel::state_t& m) {
          return m.status == kestrel::state_t::STATUS_OK || m.status == kestrel::state_t::STATUS_DEGRADED;
        },
        60.0, "the new filter's first usable state", live.received()))
        << live.output("estimator2");
    goto2 = live.run("goto2", go("10", "3"), 120.0);
    sim_status = end_flight(live, 2.0);
    live.stop_all();
    live.finish();
  }
  const std::string sim = test::read_file(dir / "sim.log");
  EXPECT_EQ(std::to_string(sim_status) + " " + std::to_string(goto1) + " " + std::to_string(goto2), "130 0 0")
      << "sim (stopped 2 s after the second arrival), goto, goto exit codes; goto said:\n" << test::read_file(dir / "goto1.log") << "\nthen:\n"
      << test::read_file(dir / "goto2.log") << "\nsim said:\n" << sim;
  EXPECT_NE(test::read_file(dir / "slam.log").find("1 estimator restarts"), std::string::npos)
      << test::read_file(dir / "slam.log");
  const std::string restarted = test::read_file(dir / "estimator2.log");
  EXPECT_NE(restarted.find("1 moved the world onto SLAM's"), std::string::npos) << restarted;
  EXPECT_NE(sim.find("contacts: 0"), std::string::npos) << sim;
  // The simulator's lock-step let the dead estimator go and took the new one in.
  EXPECT_NE(sim.find("process estimator left the lock-step session"), std::string::npos) << sim;
  EXPECT_NE(sim.find("process estimator joined the lock-step session"), std::string::npos) << sim;

  // STATE against the truth (the body's position, at the same utime): the new filter's
  // states from its first one on.
  std::map<int64_t, Eigen::Vector3d> truth;
  struct Error {
    int64_t utime = 0;
    double distance = 0.0;  // from the truth
    double sigma = 0.0;     // the largest position standard deviation STATE reports
    double nees = 0.0;      // the position error's squared Mahalanobis distance under it
  };
  std::vector<Error> errors;
  std::optional<Eigen::Vector3d> last_truth;
  transport::LogReader log((dir / "flight.lcmlog").string());
  while (auto e = log.next()) {
    const auto& data = e->data;
    if (e->channel == channel::kGroundTruth) {
      const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
      truth[m.utime] = transport::from_message(m.T_world_frame, "GROUND_TRUTH").translation();
      last_truth = truth[m.utime];
    } else if (e->channel == channel::kState) {
      const auto m = transport::decode_message<kestrel::state_t>(data.data(), data.size(), "STATE");
      if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) continue;
      // The truth nearest in time, within a millisecond (both come at the IMU's 200 Hz).
      const auto t = truth.lower_bound(m.utime - 1000);
      if (t == truth.end() || std::abs(t->first - m.utime) > 1000) continue;
      const Eigen::Vector3d error = transport::from_message(m.T_world_body, "STATE").translation() - t->second;
      ASSERT_EQ(m.cov_dim, 15);
      Eigen::Matrix3d P;
      for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col)
          P(row, col) = m.covariance[static_cast<size_t>(row)][static_cast<size_t>(col)];
      errors.push_back({m.utime, error.norm(), std::sqrt(P.diagonal().maxCoeff()), error.dot(P.ldlt().solve(error))});
    }
  }
  ASSERT_GT(errors.size(), 100u);
  // The kill: the longest silence on STATE; the new filter's states follow it.
  size_t restart = 1;
  for (size_t i = 1; i < errors.size(); ++i)
    if (errors[i].utime - errors[i - 1].utime > errors[restart].utime - errors[restart - 1].utime) restart = i;
  ASSERT_GT(errors[restart].utime - errors[restart - 1].utime, 200'000) << "the estimator was killed";
  // When the new filter's states came into the map's world: the first after which every one
  // is within 10 cm of the truth.
  size_t aligned = errors.size();
  while (aligned > restart && errors[aligned - 1].distance < 0.10) --aligned;
  ASSERT_LT(aligned, errors.size()) << "the new filter's last state is " << errors.back().distance << " m off";
  const Error& first = errors[restart];
  const double delay = aligned == restart ? 0.0 : 1e-6 * static_cast<double>(errors[aligned].utime - first.utime);
  std::printf("the new filter's first state %.3f m off (sigma %.4f m, NEES %.2f), in the map's world %.3f s later "
              "(%zu states after)\n",
              first.distance, first.sigma, first.nees, delay, errors.size() - aligned);
  // Once in CI (1 of ~15 runs) the first state was 0.58 m off with SLAM's 5 cm sigma, and
  // in the map's world 1.8 s later: most likely a correction from a keyframe across a VO break
  // nothing bridged, which SLAM no longer sends (AdapterTest.ARestartedEstimatorGetsNoWorldFrom
  // APoseAcrossAnUnbridgedVoBreak). Such a break would now fail here differently: SLAM waits for
  // a loop to place the new odometry, and the new filter may fly on its own world after its 1 s
  // (--await-world). What the new filter and SLAM said is shown if it fails.
  const std::string said = "\nthe new estimator said:\n" + test::read_file(dir / "estimator2.log") +
                           "\nslam said:\n" + test::read_file(dir / "slam.log");
  EXPECT_LT(delay, 0.5) << "a hover makes no keyframe: the world must not wait for one" << said;
  // It is as uncertain as SLAM's pose in the map's world, not as its own start in its old
  // one (1 mm): its error lies within what it reports (3 dof, chi2 at 1e-3: 16.3).
  EXPECT_LT(first.nees, 16.3) << first.distance << " m off, reporting sigma " << first.sigma << " m";
  ASSERT_TRUE(last_truth.has_value());
  std::printf("the vehicle ended at (%.3f, %.3f, %.3f)\n", last_truth->x(), last_truth->y(), last_truth->z());
  EXPECT_LT((*last_truth - Eigen::Vector3d(10.0, 3.0, 1.3)).norm(), 0.10) << "where the vehicle really ended";
}

}  // namespace
}  // namespace kestrel
