// Onboard and offboard on two "hosts": `kestrel launch all --link` puts the sim vehicle, VO,
// the estimator and the follower in one network namespace and SLAM, the mapper and the
// planner in another, joined by kestrel-link at 10 % loss, 30 ± 10 ms, 20 Mbit/s, with the
// frames crossing compressed (tools/link/split_flight.h says what is flown and measured).
// The vehicle must hold its position within 10 cm of the truth's, SLAM's corrections must
// reach the estimator and be applied, the mapper must build its map from the frames that
// crossed, and both plans asked for from the ground station must be answered and flown.
// Live, at the sensors' pace: the figures vary a little from run to run.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "test/support/test_support.h"
#include "kestrel/vo_update_t.hpp"
#include "tools/link/split_flight.h"

namespace kestrel {
namespace {

TEST(SplitFlight, OnboardAndOffboardOverALossyLinkHoldPositionAndStillGetCorrectionsPlansAndAMap) {
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  if (!std::filesystem::exists("/usr/bin/lcm-logger")) KESTREL_SKIP_ENVIRONMENT() << "lcm-logger is not installed";
  test::TempDir dir;
  link::SplitFlightOptions o;
  o.bin_dir = test::tool("launch").parent_path();
  o.out_dir = dir / "flight";
  o.loss_percent = 10;
  o.duration_s = 50;
  const link::SplitFlightResult r = link::fly_split(o);
  const auto logs = [&](const char* name) { return test::read_file(dir / "flight" / "logs" / name); };
  std::printf("holding: %d truth samples, deviation mean %.1f cm, max %.1f cm; corrections %d received, %d applied; "
              "%d plans; mapper %d keyframes, SLAM %d; link: %lld of %lld datagrams lost, %lld queue full; up %.1f Mbit/s\n",
              r.hover_samples, r.deviation_mean_m * 100, r.deviation_max_m * 100, r.corrections_received,
              r.corrections_applied, r.plans_answered, r.mapper_keyframes, r.slam_keyframes,
              static_cast<long long>(r.datagrams_lost), static_cast<long long>(r.datagrams_offered),
              static_cast<long long>(r.datagrams_queue_full), r.up_mbit_s);
  ASSERT_EQ(r.problems, "") << test::read_file(dir / "flight" / "launch.txt");
  EXPECT_EQ(r.launch_exit, 0) << test::read_file(dir / "flight" / "launch.txt");
  EXPECT_EQ(r.goto_out_exit, 0) << test::read_file(dir / "flight" / "goto_out.txt");
  EXPECT_EQ(r.goto_back_exit, 0) << test::read_file(dir / "flight" / "goto_back.txt");
  // Live: the flights out and back take longer under load, which shortens the final hold (9.7 s
  // once in CI with both cores busy); 8 s of 200 Hz truth still samples both holds.
  ASSERT_GT(r.hover_samples, 200 * 8) << "at least 8 s of holding";
  EXPECT_LE(r.deviation_max_m, 0.10);
  EXPECT_GE(r.corrections_received, 1);
  EXPECT_GE(r.corrections_applied, 1) << logs("estimator.log");
  EXPECT_GE(r.plans_answered, 2);
  std::printf("requests: %d out, %d back (a second when a plan was lost on its way down)\n", r.goto_out_attempts,
              r.goto_back_attempts);
  EXPECT_GE(r.mapper_keyframes, 3) << logs("mapper.log");
  EXPECT_GT(r.datagrams_lost, 0) << "the link lost nothing at 10 %";
  // Nothing onboard waited on the link: VO read every frame (30 Hz of the flight), STATE never
  // paused, and the filter never restarted. VO measures nearly every frame; the few it may not
  // are lost to the flight's own motion, which the live loop flies a little differently from
  // run to run (9 of 1501 in two CI runs, 11 in 1 of 19 runs alone, none in the others),
  // never to a frame that arrived damaged
  // (docs/decisions/2026-12-06-ci-time-test-code-at-O0.md).
  std::printf("onboard: VO %d frames, %d with a motion; %d STATEs, longest gap %.3f s\n", r.vo_frames, r.vo_motions,
              r.states, r.state_max_gap_s);
  for (const link::VoFailure& f : r.vo_failures)
    std::printf("  VO failed at %.3f s: status %d, %d features, %d matches, %d inliers\n", 1e-6 * double(f.utime), f.status,
                f.features, f.matches, f.inliers);
  EXPECT_GE(r.vo_frames, static_cast<int>(0.95 * 30 * o.duration_s));
  EXPECT_GE(r.vo_motions, r.vo_frames - r.vo_frames / 50);
  for (const link::VoFailure& f : r.vo_failures) EXPECT_NE(f.status, vo_update_t::STATUS_BAD_INPUT);
  EXPECT_LT(r.state_max_gap_s, 0.5);
  EXPECT_NE(logs("estimator.log").find("filter restarts 0"), std::string::npos) << logs("estimator.log");
}

}  // namespace
}  // namespace kestrel
