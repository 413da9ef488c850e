// VO + SLAM on a synthetic loop through the simulator's `floor` world (issue 6's target: ATE
// after loop closure <= 0.3x the odometry's, zero false loop closures), rendered in process
// (label integration; needs no data files: the world is built in). The `loop` flight tours four
// far-apart places of the floor and is back at its start at ~104 s, heading as it left; the
// camera is pitched 30 degrees down (at the default 10 degrees it faces blank walls at the
// tour's turnarounds and the odometry breaks for seconds, slam/README.md). 112 s at 10
// frames/s. At this rate the VO still restarts in the two sharpest turns (~35 degrees of
// heading lost each time): that lost heading is the drift the loop closures remove here, so
// this is a regression test of loop closure across odometry restarts on a long loop (where
// the VO never restarts it drifts only ~2 cm over the lap; README "SLAM figures").

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "common/numbers.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "sensors/builtin_profiles.h"
#include "slam/place/builtin_vocabulary.h"
#include "slam/sequence_run.h"
#include "metrics/evaluate.h"

namespace kestrel::slam {
namespace {

// kestrel eval's ATE (RMSE after the rigid alignment, at the estimate's frames, the ground
// truth interpolated within 20 ms): the one ATE of the project.
double ate_rmse(const Trajectory& estimate, const Trajectory& truth) {
  return metrics::evaluate(metrics::frame_times(estimate), estimate, truth, metrics::EvalOptions{}).ate.error_m.rmse;
}

TEST(SlamSimLoop, FloorLoopCutsTheOdometryDriftWithNoFalseClosure) {
  const auto start = std::chrono::steady_clock::now();
  const sim::World world = sim::load_world("floor");
  const auto flight = sim::make_flight("loop", world);
  sim::SimulationOptions so;
  so.camera.rate_hz = 10.0;
  so.camera.T_body_camera = sim::CameraOptions::default_T_body_camera(30.0);
  sim::Simulation sim(world, *flight, so);
  constexpr size_t kFrames = 1121;  // 112 s
  Trajectory truth;
  for (size_t i = 0; i < kFrames; ++i) {
    const int64_t utime = sim.frame_utime(static_cast<int64_t>(i));
    truth.push_back(utime, sim.T_world_camera(sim.seconds(utime)));
  }
  const SlamRun run = run_slam_sequence(
      kFrames, [&sim](size_t i) { return sim.render(static_cast<int64_t>(i)); }, sensors::builtin_profile("simulator"),
      vo::VoOptions{}, SlamOptions{},
      builtin_vocabulary());
  ASSERT_GT(run.vo.size(), kFrames * 95 / 100) << "the odometry lost the camera";
  const double vo_ate = ate_rmse(run.vo, truth), slam_ate = ate_rmse(run.slam, truth);
  double worst_m = 0.0, worst_rad = 0.0;
  for (const LoopError& e : loop_errors(run, truth)) {
    ASSERT_TRUE(e.has_truth);
    worst_m = std::max(worst_m, e.translation_m);
    worst_rad = std::max(worst_rad, e.rotation_rad);
  }
  std::cout << "floor loop: ATE VO " << vo_ate << " m, SLAM " << slam_ate << " m (" << slam_ate / vo_ate
            << "x), " << run.keyframes << " keyframes, " << run.loop_closures << " loop closures, worst "
            << worst_m << " m / " << worst_rad * 180.0 / kPi << " deg, "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s\n";
  EXPECT_GE(run.loop_closures, 1);
  EXPECT_LT(worst_m, 0.10) << "a false loop closure";
  EXPECT_LT(worst_rad, 3.0 * kPi / 180.0) << "a false loop closure";
  EXPECT_GT(vo_ate, 0.3) << "too little drift for the test to mean anything";
  EXPECT_LE(slam_ate, 0.3 * vo_ate);
}

}  // namespace
}  // namespace kestrel::slam
