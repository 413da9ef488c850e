// Relocalisation over a sweep of start poses in the simulator (issue 41 item 6): the room's
// figure-eight is mapped (keyframes at the true camera poses, the simulator's renderer with its
// sensor noise), then a camera hovers at each start pose of a grid over the room (positions
// and headings, most of them never a keyframe's) with no prior, for up to 6 frames. Counted:
// placed (and how many frames it took, and the time per frame tried), placed wrongly (more than
// 10 cm or 5 degrees off the truth: a false relocalisation), and never placed. Frames of another
// world (the office) against the room's map must never be placed.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <vector>

#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/renderer.h"
#include "drivers/sim/world_catalog.h"
#include "slam/backend/slam.h"
#include "slam/place/builtin_vocabulary.h"

namespace kestrel::slam {
namespace {

constexpr int kHoverFrames = 6;

Eigen::Isometry3d body_pose(const Eigen::Vector3d& p, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = p;
  return T;
}

struct Sweep {
  int starts = 0, placed = 0, wrong = 0;
  std::vector<int> frames;   // of the placed
  std::vector<double> ms;    // per frame tried
  double worst_m = 0.0, worst_deg = 0.0;
};

// Hovers a camera at each pose of `starts` in `world` on `map`; `truth_in_map` says whether the
// poses are in the map's world (else any placement is wrong).
Sweep sweep(const sim::World& world, const std::vector<Eigen::Isometry3d>& starts,
            const std::shared_ptr<const SlamMap>& map, bool truth_in_map, const SlamOptions& options = {},
            const sim::CameraOptions& camera = {}) {
  sim::Renderer renderer(world, camera, 7);
  Sweep s;
  int64_t seq = 0;
  for (const Eigen::Isometry3d& T_world_body : starts) {
    ++s.starts;
    Slam slam(map, options);
    const Eigen::Isometry3d T_world_camera = T_world_body * camera.T_body_camera;
    for (int i = 0; i < kHoverFrames; ++i) {
      const RgbdFrame frame = renderer.render(T_world_camera, 1'000'000 + 33'333 * i, ++seq);
      const auto t0 = std::chrono::steady_clock::now();
      const SlamStep step = slam.add(frame, Eigen::Isometry3d::Identity());  // hovering: the odometry stays
      s.ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (!step.relocalised) continue;
      const Eigen::Isometry3d E = T_world_camera.inverse() * slam.relocalisation()->T_world_camera;
      const double m = E.translation().norm(), deg = so3::angle(E.linear()) * 180.0 / kPi;
      if (!truth_in_map || m > 0.10 || deg > 5.0) {
        ++s.wrong;
      } else {
        ++s.placed;
        s.frames.push_back(i + 1);
        s.worst_m = std::max(s.worst_m, m);
        s.worst_deg = std::max(s.worst_deg, deg);
      }
      break;
    }
  }
  return s;
}

// A map of `flight` in `world`: its camera every 0.1 s for `seconds`, at the true poses.
std::shared_ptr<const SlamMap> map_of_flight(const sim::World& world, const sim::Flight& flight, double seconds,
                                             const sim::CameraOptions& camera = {}) {
  sim::Renderer renderer(world, camera, 3);
  Slam mapping(SlamOptions{}, builtin_vocabulary());
  for (int k = 0; k <= static_cast<int>(std::lround(seconds * 10.0)); ++k) {
    const Eigen::Isometry3d T_world_camera = flight.state(0.1 * k).T_world_body * camera.T_body_camera;
    mapping.add(renderer.render(T_world_camera, 1'000'000 + 100'000 * k, k), T_world_camera);
  }
  return std::make_shared<const SlamMap>(mapping.map());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

TEST(RelocalisationSweep, StartsOverTheMappedRoomArePlacedRightAndNoneElsewhere) {
  const sim::World room = sim::load_world("room");
  // The map: the figure-eight's camera every 0.1 s for 20 s, at the true poses.
  const auto map = map_of_flight(room, *sim::make_flight("figure8", room), 20.0);

  // Start poses: a 3 x 3 grid over the take-off area, 1.3 m up, eight headings each.
  const Eigen::Vector4d takeoff = room.start();
  std::vector<Eigen::Isometry3d> starts;
  for (double dx : {-0.5, 0.0, 0.5})
    for (double dy : {-0.5, 0.0, 0.5})
      for (int h = 0; h < 8; ++h)
        starts.push_back(body_pose(takeoff.head<3>() + Eigen::Vector3d(dx, dy, 0.0), takeoff[3] + h * kPi / 4));
  const Sweep in_room = sweep(room, starts, map, true);
  const sim::World office = sim::load_world("office");
  std::vector<Eigen::Isometry3d> elsewhere;
  for (int h = 0; h < 8; ++h) {
    for (double dx : {-1.0, 0.0, 1.0})
      elsewhere.push_back(body_pose(office.start().head<3>() + Eigen::Vector3d(dx, 0.0, 0.0), h * kPi / 4));
  }
  const Sweep other = sweep(office, elsewhere, map, false);

  std::vector<double> frames(in_room.frames.begin(), in_room.frames.end());
  std::cout << "room map of " << map->keyframes.size() << " keyframes; " << in_room.starts << " starts in the room: "
            << in_room.placed << " placed (median " << median(frames) << " frames, worst " << in_room.worst_m * 100.0
            << " cm / " << in_room.worst_deg << " deg), " << in_room.wrong << " placed wrongly, "
            << in_room.starts - in_room.placed - in_room.wrong << " never; " << other.starts << " starts in the office: "
            << other.wrong << " placed (wrongly); median " << median(in_room.ms) << " ms per frame tried\n";
  EXPECT_EQ(in_room.wrong, 0) << "a false relocalisation";
  EXPECT_EQ(other.wrong, 0) << "a false relocalisation in a world the map has not seen";
  EXPECT_GE(in_room.placed, in_room.starts / 4) << "the headings the figure-eight looked along at least";
}

// A corridor of brick and floor tiles (the floor world's, from its take-off): near-copies of
// every corner across the view. The loop flight's first 12 s are mapped; the camera hovers
// where the flight passed, 0.2 m to either side, turned 10 degrees either way. The loops'
// strict ratio test (0.6) leaves fewer matches with the right keyframe there; a placement's
// (RelocalisationOptions::match_ratio) must place more of the starts, and none wrongly. That
// is measured with a fixed exposure, whose frames wash out under the floor's lamps: with fewer
// corners left the repeated ones decide. With the simulated camera's auto-exposure (as it
// flies) the corridor is easier: placed right at both ratios, never wrongly.
TEST(RelocalisationSweep, StartsInACorridorOfRepeatingTilesArePlacedRightAndSooner) {
  const sim::World floor = sim::load_world("floor");
  const auto flight = sim::make_flight("loop", floor);
  std::vector<Eigen::Isometry3d> starts;
  for (double t : {1.5, 4.5, 7.5, 10.5}) {
    const Eigen::Isometry3d on_path = flight->state(t).T_world_body;
    const double yaw = std::atan2(on_path.linear()(1, 0), on_path.linear()(0, 0));
    for (double side : {-0.2, 0.2})
      for (double turn : {-10.0, 10.0}) {
        const Eigen::Vector3d left(-std::sin(yaw), std::cos(yaw), 0.0);
        starts.push_back(body_pose(on_path.translation() + side * left, yaw + turn * kPi / 180.0));
      }
  }
  SlamOptions strict;
  strict.relocalisation.match_ratio = 0.6;
  const auto run = [&](const char* name, const sim::CameraOptions& camera) {
    const auto map = map_of_flight(floor, *flight, 12.0, camera);
    const Sweep loose_sweep = sweep(floor, starts, map, true, SlamOptions{}, camera);
    const Sweep strict_sweep = sweep(floor, starts, map, true, strict, camera);
    std::vector<double> loose_frames(loose_sweep.frames.begin(), loose_sweep.frames.end());
    std::vector<double> strict_frames(strict_sweep.frames.begin(), strict_sweep.frames.end());
    std::cout << name << ": floor corridor map of " << map->keyframes.size() << " keyframes; " << starts.size()
              << " starts: ratio " << SlamOptions{}.relocalisation.match_ratio << ": " << loose_sweep.placed
              << " placed (median " << median(loose_frames) << " frames, worst " << loose_sweep.worst_m * 100.0
              << " cm / " << loose_sweep.worst_deg << " deg), " << loose_sweep.wrong << " wrongly; ratio 0.6: "
              << strict_sweep.placed << " placed (median " << median(strict_frames) << " frames), "
              << strict_sweep.wrong << " wrongly\n";
    EXPECT_EQ(loose_sweep.wrong, 0) << name << ": a false relocalisation";
    EXPECT_EQ(strict_sweep.wrong, 0) << name << ": a false relocalisation";
    EXPECT_GE(loose_sweep.placed, static_cast<int>(starts.size()) * 3 / 4) << name;
    return std::make_pair(loose_sweep.placed, strict_sweep.placed);
  };
  sim::CameraOptions fixed_exposure;
  fixed_exposure.rgb.max_mean_grey = 0.0;
  const auto [loose, strict_placed] = run("fixed exposure", fixed_exposure);
  EXPECT_GT(loose, strict_placed) << "the placement's ratio places more where the repeated corners decide";
  run("auto-exposure", sim::CameraOptions{});
}

}  // namespace
}  // namespace kestrel::slam
