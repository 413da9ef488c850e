// The Mapper: SLAM keyframes, the rebuild after a loop closure (the rebuilt map equals the map
// built at the corrected poses from the start), the keyframe budget, and bad input (NaN or
// zero depth never marks a cell; a NaN pose or a frame without depth is an InputError).
#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "common/numbers.h"
#include "mapper/mapper.h"
#include "mapper/scan.h"
#include "test/mapper/scene.h"

namespace kestrel::mapper {
namespace {

using test::Scene;

// Camera poses sweeping the room, 0.2 s apart.
std::vector<Eigen::Isometry3d> sweep(int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i) {
    const double a = -0.8 + 1.6 * i / (n - 1);
    poses.push_back(test::look_at({-1.2 + 0.05 * i, 0.013, 1.2},
                                  {-1.2 + 3.0 * std::cos(a), 3.0 * std::sin(a), 0.7}));
  }
  return poses;
}

void expect_same_maps(const VoxelMap& a, const VoxelMap& b) {
  ASSERT_EQ(a.num_cells(), b.num_cells());
  a.for_each_cell([&](const Key& k, float v) { ASSERT_EQ(b.log_odds(k), v); });
}

TEST(Mapper, RebuildAfterLoopClosureEqualsTheMapAtTheCorrectedPoses) {
  const Scene scene = test::room_with_a_box();
  const auto truth = sweep(8);
  MapperOptions options;
  options.rebuild_interval_s = 0.0;
  Mapper drifted(options), direct(options);
  std::vector<GraphKeyframe> graph, true_graph;
  for (size_t i = 0; i < truth.size(); ++i) {
    const int64_t utime = 1000000 + 200000 * static_cast<int64_t>(i);
    const RgbdFrame frame = scene.render(test::kinect_camera(), truth[i], utime);
    drifted.buffer_frame(frame);
    direct.buffer_frame(frame);
    // Odometry drift: 3 cm and 0.5 degrees more per keyframe.
    Eigen::Isometry3d T = truth[i];
    T.translation() += Eigen::Vector3d(0.03, -0.02, 0.01) * static_cast<double>(i);
    T.rotate(Eigen::AngleAxisd(0.5 * kPi / 180.0 * i, Eigen::Vector3d::UnitY()));
    graph.push_back({static_cast<int64_t>(i), utime, T});
    true_graph.push_back({static_cast<int64_t>(i), utime, truth[i]});
    const GraphResult r = drifted.apply_graph(graph);
    EXPECT_EQ(r.inserted.size(), 1u);
    EXPECT_FALSE(r.rebuilt);
    direct.apply_graph(true_graph);
  }
  ASSERT_GT(direct.map().num_occupied(), 100u);
  // The loop closes: SLAM moves every keyframe back to the truth.
  const GraphResult r = drifted.apply_graph(true_graph);
  EXPECT_EQ(r.moved.size(), truth.size() - 1);  // keyframe 0 did not drift
  EXPECT_TRUE(r.rebuilt);
  EXPECT_EQ(r.rebuild_keyframes, truth.size());
  expect_same_maps(drifted.map(), direct.map());
}

// A Kinect's depth is taken up to 31 ms before its colour: SLAM's keyframe pose is the
// colour camera's, and the depth belongs where the camera was at the depth's time. The map of
// keyframes given with their T_camera_depth equals the map of the same depth images placed at
// their depth-time poses, and differs from the one that ignores it.
TEST(Mapper, AKeyframesDepthGoesInAtTheCameraPoseOfItsOwnTime) {
  const Scene scene = test::room_with_a_box();
  const auto colour_poses = sweep(6);
  // 25 ms at 0.5 m/s and 30 deg/s, backwards: the depth's camera 1.25 cm and 0.75 deg behind.
  Eigen::Isometry3d T_camera_depth = Eigen::Isometry3d::Identity();
  T_camera_depth.translation() << -0.0125, 0.0, 0.0;
  T_camera_depth.rotate(Eigen::AngleAxisd(-0.75 * kPi / 180.0, Eigen::Vector3d::UnitY()));
  MapperOptions options;
  Mapper timed(options), at_depth(options), untimed(options);
  std::vector<GraphKeyframe> graph, depth_graph, colour_graph;
  for (size_t i = 0; i < colour_poses.size(); ++i) {
    const int64_t utime = 1000000 + 200000 * static_cast<int64_t>(i);
    const Eigen::Isometry3d T_world_depth = colour_poses[i] * T_camera_depth;
    const RgbdFrame frame = scene.render(test::kinect_camera(), T_world_depth, utime);
    for (Mapper* m : {&timed, &at_depth, &untimed}) m->buffer_frame(frame);
    graph.push_back({static_cast<int64_t>(i), utime, colour_poses[i], T_camera_depth});
    depth_graph.push_back({static_cast<int64_t>(i), utime, T_world_depth});
    colour_graph.push_back({static_cast<int64_t>(i), utime, colour_poses[i]});
  }
  timed.apply_graph(graph);
  at_depth.apply_graph(depth_graph);
  untimed.apply_graph(colour_graph);
  ASSERT_GT(timed.map().num_occupied(), 100u);
  expect_same_maps(timed.map(), at_depth.map());
  size_t differing = 0;
  untimed.map().for_each_cell([&](const Key& k, float v) { differing += timed.map().log_odds(k) != v; });
  EXPECT_GT(differing, untimed.map().num_cells() / 20) << "the offset should matter for this test to mean anything";
}

TEST(Mapper, RebuildStartsFromTheLastCheckpointBeforeTheFirstMovedKeyframe) {
  const Scene scene = test::room_with_a_box();
  const auto truth = sweep(12);
  MapperOptions options;
  options.rebuild_interval_s = 0.0;
  options.checkpoint_every = 4;
  Mapper mapper(options), direct(options);
  std::vector<GraphKeyframe> graph;
  std::vector<RgbdFrame> frames;
  for (size_t i = 0; i < truth.size(); ++i) {
    const int64_t utime = 1000000 + 200000 * static_cast<int64_t>(i);
    frames.push_back(scene.render(test::kinect_camera(), truth[i], utime));
    mapper.buffer_frame(frames.back());
    direct.buffer_frame(frames.back());
    graph.push_back({static_cast<int64_t>(i), utime, truth[i]});
    mapper.apply_graph(graph);
  }
  EXPECT_EQ(mapper.checkpoints(), 3u);  // after keyframes 4, 8 and 12
  // A loop closure moves keyframes 9 to 11 (by 5 cm): the checkpoint after keyframe 8 holds.
  std::vector<GraphKeyframe> corrected = graph;
  for (size_t i = 9; i < corrected.size(); ++i) corrected[i].T_world_camera.translation().x() += 0.05;
  const GraphResult r = mapper.apply_graph(corrected);
  EXPECT_TRUE(r.rebuilt);
  EXPECT_EQ(r.moved, (std::vector<int64_t>{9, 10, 11}));
  EXPECT_EQ(r.reinserted, 4u) << "keyframes 8 to 11 again, 0 to 7 from the checkpoint";
  EXPECT_EQ(mapper.checkpoints(), 3u) << "the stale third checkpoint is replaced";
  direct.apply_graph(corrected);
  ASSERT_GT(direct.map().num_occupied(), 100u);
  expect_same_maps(mapper.map(), direct.map());
  // Moving the first keyframe leaves no checkpoint usable.
  corrected[0].T_world_camera.translation().y() += 0.05;
  EXPECT_EQ(mapper.apply_graph(corrected).reinserted, truth.size());
  // The budget: no room for a copy means no checkpoints, and the rebuild still works.
  MapperOptions tight = options;
  tight.checkpoint_megabytes = 0.0;
  Mapper thin(tight);
  for (size_t i = 0; i < truth.size(); ++i) {
    thin.buffer_frame(frames[i]);
    thin.apply_graph(std::vector<GraphKeyframe>(graph.begin(), graph.begin() + static_cast<long>(i) + 1));
  }
  EXPECT_EQ(thin.checkpoints(), 0u);
  EXPECT_EQ(thin.apply_graph(corrected).reinserted, truth.size());
  expect_same_maps(thin.map(), mapper.map());
}

// A second flight on a saved map (the first flight's keyframes restored from its journal)
// starts its sensor time again, so its keyframes share times with the first's; here the box was
// moved between the flights. The live map took the first flight, then the second, and a rebuild
// must insert them in that order too: interleaved by time, the clamped log-odds of the cells
// the box left (and moved to) come out otherwise.
TEST(Mapper, ARebuildKeepsTheOrderTheKeyframesWereStoredInAcrossFlightsThatShareTimes) {
  const Scene before = test::room_with_a_box();
  Scene after = before;
  after.clear_boxes();
  after.add_box(Eigen::Vector3d(0.8, 0.5, 0.0), Eigen::Vector3d(1.4, 1.2, 0.9));
  const auto poses = sweep(8);
  MapperOptions options;
  options.rebuild_interval_s = 0.0;
  options.checkpoint_every = 3;
  const auto flight = [&](Mapper& mapper, const Scene& scene, int64_t first_id) {
    std::vector<GraphKeyframe> graph;
    for (size_t i = 0; i < poses.size(); ++i) {
      const int64_t utime = 1000000 + 200000 * static_cast<int64_t>(i);
      mapper.buffer_frame(scene.render(test::kinect_camera(), poses[i], utime));
      graph.push_back({first_id + static_cast<int64_t>(i), utime, poses[i]});
    }
    EXPECT_EQ(mapper.apply_graph(graph).inserted.size(), poses.size());
    return graph;
  };
  Mapper first(options);
  const std::vector<GraphKeyframe> first_graph = flight(first, before, 0);
  // The second flight's mapper starts from the first's keyframes, as from its journal.
  Mapper second(options);
  for (const GraphKeyframe& g : first_graph) second.restore_keyframe(g, first.keyframes().find(g.id)->frame);
  second.rebuild();
  expect_same_maps(second.map(), first.map());
  std::vector<GraphKeyframe> graph = flight(second, after, 100);
  const VoxelMap live = second.map();
  // Interleaved by time, the same keyframes make another map: the order matters for this test.
  Mapper interleaved(options);
  for (size_t i = 0; i < poses.size(); ++i) {
    interleaved.restore_keyframe(first_graph[i], first.keyframes().find(first_graph[i].id)->frame);
    interleaved.restore_keyframe(graph[i], second.keyframes().find(graph[i].id)->frame);
  }
  interleaved.rebuild();
  ASSERT_EQ(interleaved.map().num_cells(), live.num_cells());
  size_t differing = 0;
  live.for_each_cell([&](const Key& k, float v) { differing += interleaved.map().log_odds(k) != v; });
  ASSERT_GT(differing, 20u) << "where the box was and went, the flights' order should show";

  second.rebuild_from_scratch();
  expect_same_maps(second.map(), live);
  // A loop closure that moves the second flight's last keyframe and back: the rebuild from the
  // checkpoints gives the map again.
  graph.back().T_world_camera.translation().x() += 0.05;
  ASSERT_TRUE(second.apply_graph(graph).rebuilt);
  graph.back().T_world_camera.translation().x() -= 0.05;
  const GraphResult back = second.apply_graph(graph);
  ASSERT_TRUE(back.rebuilt);
  EXPECT_LT(back.reinserted, 2 * poses.size()) << "a checkpoint of the live sequence was used";
  expect_same_maps(second.map(), live);
}

TEST(Mapper, RebuildsAreRateLimitedAndMissingFramesCounted) {
  const Scene scene = test::room_with_a_box();
  const auto truth = sweep(3);
  MapperOptions options;
  options.rebuild_interval_s = 1.0;
  Mapper mapper(options);
  std::vector<GraphKeyframe> graph;
  for (int i = 0; i < 3; ++i) {
    const int64_t utime = 200000 * (i + 1);
    mapper.buffer_frame(scene.render(test::kinect_camera(160, 120), truth[static_cast<size_t>(i)], utime));
    graph.push_back({i, utime, truth[static_cast<size_t>(i)]});
  }
  graph.push_back({99, 123, truth[0]});  // names a frame that never came
  GraphResult r = mapper.apply_graph(graph);
  EXPECT_EQ(r.inserted.size(), 3u);
  EXPECT_EQ(r.missing, 1u);
  graph[1].T_world_camera.translation().x() += 0.1;
  r = mapper.apply_graph(graph);
  EXPECT_TRUE(r.rebuilt);  // the first rebuild is always allowed
  graph[1].T_world_camera.translation().x() += 0.1;
  r = mapper.apply_graph(graph);
  EXPECT_EQ(r.moved, std::vector<int64_t>{1});
  EXPECT_FALSE(r.rebuilt) << "a second rebuild within 1 s of sensor time waits";
  EXPECT_EQ(mapper.rebuilds(), 1u);
}

// The scene's frame (depth only) with a colour image: a pattern of both coordinates.
RgbdFrame with_colour(RgbdFrame frame) {
  frame.rgb.create(frame.depth_mm.size(), CV_8UC3);
  for (int v = 0; v < frame.rgb.rows; ++v)
    for (int u = 0; u < frame.rgb.cols; ++u)
      frame.rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uint8_t>(u), static_cast<uint8_t>(v), static_cast<uint8_t>(u + 3 * v));
  return frame;
}

// A frame buffered without its colour, with a source that makes it: the colour is made only
// for frames asked for, once, and comes out as from the whole frame; a source that fails
// leaves the frame its depth.
TEST(Mapper, DeferredColourIsMadeOnlyForTheFramesAskedForAndAsFromTheWholeFrame) {
  const Scene scene = test::room_with_a_box();
  const auto poses = sweep(3);
  Mapper whole, deferred;
  int made[3] = {0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    const RgbdFrame frame = with_colour(scene.render(test::kinect_camera(), poses[static_cast<size_t>(i)], 1000 + i));
    whole.buffer_frame(frame);
    RgbdFrame without = frame;
    without.rgb = cv::Mat();
    deferred.buffer_frame(without, "frame", [&made, i, rgb = frame.rgb]() -> cv::Mat {
      ++made[i];
      if (i == 2) throw InputError("CAMERA_RGBD: corrupt JPEG colour image (test)");
      return rgb;
    });
  }
  EXPECT_THROW(deferred.buffer_frame(with_colour(scene.render(test::kinect_camera(), poses[0], 2000)), "frame",
                                     [] { return cv::Mat(); }),
               std::invalid_argument) << "colour given twice";
  const RgbdFrame* a = deferred.buffered(1001);
  const RgbdFrame* b = whole.buffered(1001);
  ASSERT_TRUE(a != nullptr && b != nullptr);
  ASSERT_FALSE(a->rgb.empty());
  EXPECT_EQ(cv::norm(a->rgb, b->rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a->depth_mm, b->depth_mm, cv::NORM_INF), 0.0);
  deferred.buffered(1001);
  EXPECT_EQ(made[0], 0);
  EXPECT_EQ(made[1], 1) << "made once";
  EXPECT_EQ(deferred.colour_lost(), 0u);
  // A keyframe of the frame whose colour fails: stored and inserted with its depth alone.
  const GraphResult r = deferred.apply_graph({{7, 1002, poses[2]}});
  EXPECT_EQ(r.inserted.size(), 1u);
  EXPECT_EQ(made[2], 1);
  EXPECT_EQ(deferred.colour_lost(), 1u);
  EXPECT_EQ(deferred.colour_lost_reason(), "CAMERA_RGBD: corrupt JPEG colour image (test)");
  const StoredKeyframe* kf = deferred.keyframes().find(7);
  ASSERT_NE(kf, nullptr);
  EXPECT_TRUE(kf->frame.rgb.empty());
  EXPECT_FALSE(kf->frame.depth_mm.empty());
  EXPECT_GT(deferred.map().num_occupied(), 0u);
}

TEST(Mapper, OutOfOrderFramesAndBadPosesAreInputErrors) {
  const Scene scene = test::room_with_a_box();
  Mapper mapper;
  const RgbdFrame frame = scene.render(test::kinect_camera(64, 48), sweep(2)[0], 1000);
  mapper.buffer_frame(frame);
  EXPECT_THROW(mapper.buffer_frame(frame), InputError);  // same utime again
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = static_cast<double>(NAN);
  EXPECT_THROW(mapper.insert(frame, nan_pose), InputError);
  RgbdFrame no_depth = frame;
  no_depth.depth_mm = cv::Mat();
  EXPECT_THROW(mapper.insert(no_depth, Eigen::Isometry3d::Identity()), InputError);
  EXPECT_EQ(mapper.map().num_cells(), 0u);
}

TEST(Mapper, NanAndZeroDepthNeverMarkCells) {
  const Scene scene = test::room_with_a_box();
  const Eigen::Isometry3d T = sweep(2)[1];
  const RgbdFrame frame = scene.render(test::kinect_camera(160, 120), T, 1000);
  // Depth from a float source with holes: NaN, infinities, zero and negative readings.
  cv::Mat metres = depth_to_metres(frame.depth_mm);
  cv::Mat holes = frame.depth_mm.clone();
  const float bad[] = {NAN, INFINITY, -INFINITY, 0.0f, -1.0f};
  for (int v = 0; v < metres.rows; ++v)
    for (int u = 0; u < metres.cols; ++u)
      if ((u * 7 + v * 3) % 4 == 0) {
        metres.at<float>(v, u) = bad[(u + v) % 5];
        holes.at<uint16_t>(v, u) = 0;
      }
  RgbdFrame with_nan = frame;
  with_nan.depth_mm = depth_to_millimetres(metres);
  RgbdFrame with_zero = frame;
  with_zero.depth_mm = holes;
  RgbdFrame empty = frame;
  cv::Mat all_nan = metres.clone();
  all_nan.setTo(NAN);
  empty.depth_mm = depth_to_millimetres(all_nan);
  for (const bool discretize : {false, true}) {
    MapperOptions options;
    options.scan.stride = 1;
    options.scan.discretize = discretize;
    Mapper a(options), b(options);
    a.insert(with_nan, T);
    b.insert(with_zero, T);
    expect_same_maps(a.map(), b.map());  // a NaN reading is no reading
    ASSERT_GT(a.map().num_cells(), 0u);

    // All depth missing: nothing at all, not even the camera's own cell.
    Mapper c(options);
    c.insert(empty, T);
    EXPECT_EQ(c.map().num_cells(), 0u) << "discretize " << discretize;
  }
}

TEST(KeyframeStore, BudgetThinsCrowdedViewsFirst) {
  RgbdFrame frame;
  frame.camera = test::kinect_camera(128, 96);
  frame.depth_mm = cv::Mat(96, 128, CV_16UC1, cv::Scalar(1000));
  KeyframeOptions options;
  options.max_megabytes = 10.5 * 128 * 96 * 2 / 1e6;  // room for about 10 keyframes
  KeyframeStore store(options);
  Eigen::Isometry3d lone = Eigen::Isometry3d::Identity();
  lone.translation() = Eigen::Vector3d(5.0, 5.0, 1.0);
  store.add({0, 0, lone, frame});
  for (int i = 1; i <= 30; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation().x() = 0.01 * i;  // all in one bin
    store.add({i, i, T, frame});
  }
  EXPECT_LE(store.bytes(), options.max_megabytes * 1e6);
  EXPECT_GT(store.size(), 5u);
  EXPECT_TRUE(store.contains(0)) << "the only view of a place is kept";
  EXPECT_TRUE(store.contains(30)) << "the newest keyframe is kept";
  EXPECT_FALSE(store.contains(1)) << "the oldest of the crowded bin goes first";
  EXPECT_EQ(store.dropped() + store.size(), 31u);
}

}  // namespace
}  // namespace kestrel::mapper
