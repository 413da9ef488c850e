// kestrel-map and kestrel-mapper as built tools: the offline map of a small synthetic TUM
// folder equals the library's (also with --discretize), renders and the PLY are written, a
// mapper's journal gives the map the mapper had, and usage errors and bad input give the
// documented exit codes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/image/image_io.h"
#include "common/trajectory.h"
#include "common/transport/convert.h"
#include "mapper/keyframe_journal.h"
#include "mapper/mapper.h"
#include "mapper/octree_io.h"
#include "test/mapper/scene.h"
#include "test/support/test_support.h"

namespace kestrel::mapper {
namespace {

namespace fs = std::filesystem;

// A TUM-format folder (ROS default intrinsics, 640x480) of the synthetic room seen from 6
// poses, and its trajectory; returns the frames as the tool will read them.
std::vector<std::pair<RgbdFrame, Eigen::Isometry3d>> write_sequence(const fs::path& dir) {
  test::Scene scene(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(3.0, 2.0, 2.5));
  scene.add_box(Eigen::Vector3d(0.8, -0.4, 0.0), Eigen::Vector3d(1.4, 0.3, 0.9));
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream rgb_list(dir / "rgb.txt"), depth_list(dir / "depth.txt");
  Trajectory truth;
  std::vector<std::pair<RgbdFrame, Eigen::Isometry3d>> frames;
  for (int i = 0; i < 6; ++i) {
    const int64_t utime = 1000000 + 100000 * i;
    const Eigen::Isometry3d T = test::look_at({-1.2 + 0.1 * i, 0.013, 1.2}, {2.0, 0.6 - 0.3 * i, 0.7});
    RgbdFrame f = scene.render(test::kinect_camera(), T, utime);
    const std::string name = std::to_string(utime / 1000000) + "." + std::to_string(utime % 1000000);
    cv::Mat raw;
    f.depth_mm.convertTo(raw, CV_16UC1, 5.0);  // TUM's 1/5000 m units
    image::write_png((dir / "depth" / (name + ".png")).string(), raw);
    image::write_png((dir / "rgb" / (name + ".png")).string(), cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 120, 150)));
    rgb_list << name << " rgb/" << name << ".png\n";
    depth_list << name << " depth/" << name << ".png\n";
    truth.push_back(utime, T);
    frames.emplace_back(std::move(f), T);
  }
  write_tum_trajectory((dir / "truth.txt").string(), truth);
  return frames;
}

TEST(MapTool, BuildsTheLibrarysMapAndRendersIt) {
  kestrel::test::TempDir tmp;
  const auto frames = write_sequence(tmp / "seq");
  const auto r = kestrel::test::run({kestrel::test::tool("map").string(), "--tum", (tmp / "seq").string(),
                                     "--poses", (tmp / "seq/truth.txt").string(), "--out",
                                     (tmp / "map.ot").string(), "--png", (tmp / "top.png").string(),
                                     "--view-png", (tmp / "view.png").string(), "--slice-png",
                                     (tmp / "slice.png").string(), "--ply", (tmp / "cloud.ply").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames inserted: 6"), std::string::npos) << r.out;
  Mapper reference;
  for (const auto& [frame, T] : frames) reference.insert(frame, T);
  const VoxelMap map = read_map_file((tmp / "map.ot").string());
  ASSERT_EQ(map.num_cells(), reference.map().num_cells());
  reference.map().for_each_cell([&](const Key& k, float v) { ASSERT_EQ(map.log_odds(k), v); });
  for (const char* png : {"top.png", "view.png", "slice.png"}) {
    EXPECT_FALSE(image::read_image((tmp / png).string()).empty()) << png;
  }
  std::ifstream ply(tmp / "cloud.ply");
  std::string magic;
  ply >> magic;
  EXPECT_EQ(magic, "ply");

  // Compared with itself, the map agrees completely.
  const auto again = kestrel::test::run({kestrel::test::tool("map").string(), "--tum", (tmp / "seq").string(),
                                         "--poses", (tmp / "seq/truth.txt").string(), "--out",
                                         (tmp / "again.bt").string(), "--compare", (tmp / "map.ot").string()});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("class agreement 1.0000"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("known here only 0, there only 0; free here and occupied there 0, occupied here and free there 0"),
            std::string::npos) << again.out;

  // --discretize: the library's endpoint-discretised map, a different one from the default's.
  const auto discretized = kestrel::test::run({kestrel::test::tool("map").string(), "--tum", (tmp / "seq").string(),
                                               "--poses", (tmp / "seq/truth.txt").string(), "--out",
                                               (tmp / "discretized.ot").string(), "--discretize"});
  ASSERT_EQ(discretized.exit_code, 0) << discretized.err;
  MapperOptions discretize;
  discretize.scan.discretize = true;
  Mapper discretized_reference(discretize);
  for (const auto& [frame, T] : frames) discretized_reference.insert(frame, T);
  const VoxelMap discretized_map = read_map_file((tmp / "discretized.ot").string());
  ASSERT_EQ(discretized_map.num_cells(), discretized_reference.map().num_cells());
  discretized_reference.map().for_each_cell([&](const Key& k, float v) { ASSERT_EQ(discretized_map.log_odds(k), v); });
  EXPECT_NE(discretized_map.num_cells(), map.num_cells());

  // The surface-only reference: every hit cell occupied, no free space at all.
  const auto surface = kestrel::test::run({kestrel::test::tool("map").string(), "--tum", (tmp / "seq").string(),
                                           "--poses", (tmp / "seq/truth.txt").string(), "--out",
                                           (tmp / "surface.ot").string(), "--surface-only"});
  ASSERT_EQ(surface.exit_code, 0) << surface.err;
  const VoxelMap truth = read_map_file((tmp / "surface.ot").string());
  EXPECT_GT(truth.num_cells(), 100u);
  EXPECT_EQ(truth.num_occupied(), truth.num_cells());
  size_t hit_cells = 0;
  reference.map().for_each_cell([&](const Key& k, float) { hit_cells += truth.occupancy(k) == Occupancy::kOccupied; });
  EXPECT_EQ(hit_cells, truth.num_cells()) << "every surface cell was seen by the full map too";
}

// A flight's journal (kestrel mapper --journal) made into a map offline: the map the mapper
// had, i.e. the keyframes' frames at the poses of the graph that brought them.
TEST(MapTool, BuildsTheMapOfAMappersJournal) {
  kestrel::test::TempDir tmp;
  const auto frames = write_sequence(tmp / "seq");
  Mapper live;
  std::vector<GraphKeyframe> graph;
  {
    JournalWriter journal((tmp / "mapper.journal").string());
    for (size_t i = 0; i < frames.size(); ++i) {
      kestrel::slam_keyframe_t k{};
      k.id = static_cast<int64_t>(i);
      k.utime = frames[i].first.utime;
      k.T_world_camera = transport::to_message(frames[i].second);
      k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
      live.buffer_frame(frames[i].first);
      graph.push_back(to_graph_keyframe(k, "test"));
      journal.keyframe(k, decimate(frames[i].first, live.options().scan.stride));
    }
  }
  live.apply_graph(graph);
  const auto r = kestrel::test::run({kestrel::test::tool("map").string(), "--journal",
                                     (tmp / "mapper.journal").string(), "--out", (tmp / "flight.ot").string(),
                                     "--png", (tmp / "flight.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("keyframes restored from the journal: 6"), std::string::npos) << r.out;
  const VoxelMap map = read_map_file((tmp / "flight.ot").string());
  ASSERT_EQ(map.num_cells(), live.map().num_cells());
  live.map().for_each_cell([&](const Key& k, float v) { ASSERT_EQ(map.log_odds(k), v); });
  EXPECT_FALSE(image::read_image((tmp / "flight.png").string()).empty());

  // Not a journal: exit 3 naming it. Both inputs, or --surface-only with a journal: usage.
  std::ofstream(tmp / "notes.txt") << "notes\n";
  const std::string tool = kestrel::test::tool("map").string();
  const auto bad = kestrel::test::run({tool, "--journal", (tmp / "notes.txt").string(), "--out", (tmp / "m.bt").string()});
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_NE(bad.err.find("notes.txt: not a kestrel mapper journal"), std::string::npos) << bad.err;
  const auto missing = kestrel::test::run({tool, "--journal", (tmp / "none.journal").string(), "--out", (tmp / "m.bt").string()});
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("none.journal: no such file"), std::string::npos) << missing.err;
  EXPECT_EQ(kestrel::test::run({tool, "--journal", (tmp / "mapper.journal").string(), "--tum", (tmp / "seq").string(),
                                "--poses", (tmp / "seq/truth.txt").string(), "--out", (tmp / "m.bt").string()})
                .exit_code,
            2);
  EXPECT_EQ(kestrel::test::run({tool, "--journal", (tmp / "mapper.journal").string(), "--surface-only", "--out",
                                (tmp / "m.bt").string()})
                .exit_code,
            2);
}

TEST(MapTool, UsageErrorsAndBadInput) {
  kestrel::test::TempDir tmp;
  const std::string map = kestrel::test::tool("map").string();
  EXPECT_EQ(kestrel::test::run({map, "--help"}).exit_code, 0);
  EXPECT_EQ(kestrel::test::run({map, "--tum", tmp.path().string()}).exit_code, 2);  // no --poses/--out
  EXPECT_EQ(kestrel::test::run({map, "--tum", (tmp / "nothing").string(), "--poses", "x.txt", "--out",
                                (tmp / "m.bt").string()})
                .exit_code,
            3);
  write_sequence(tmp / "seq");
  const auto bad_ext = kestrel::test::run({map, "--tum", (tmp / "seq").string(), "--poses",
                                           (tmp / "seq/truth.txt").string(), "--out", (tmp / "m.txt").string()});
  EXPECT_EQ(bad_ext.exit_code, 3);
  EXPECT_NE(bad_ext.err.find("m.txt"), std::string::npos) << bad_ext.err;
  const auto bad_value = kestrel::test::run({map, "--tum", (tmp / "seq").string(), "--poses",
                                             (tmp / "seq/truth.txt").string(), "--out", (tmp / "m.bt").string(),
                                             "--prob-hit", "0.3"});
  EXPECT_EQ(bad_value.exit_code, 2);
  EXPECT_NE(bad_value.err.find("prob-hit"), std::string::npos) << bad_value.err;

  const std::string mapper = kestrel::test::tool("mapper").string();
  EXPECT_EQ(kestrel::test::run({mapper, "--help"}).exit_code, 0);
  EXPECT_EQ(kestrel::test::run({mapper, "--pose-source", "magic"}).exit_code, 2);
  EXPECT_EQ(kestrel::test::run({mapper, "--resolution", "-1"}).exit_code, 2);
}

}  // namespace
}  // namespace kestrel::mapper
