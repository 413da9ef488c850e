// Maps from elsewhere: ROS maps (orientation, thresholds, malformed files named in errors)
// and OctoMaps projected over a height band.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/image/image_io.h"
#include "mapper/octree_io.h"
#include "planner/map_sources.h"
#include "test/support/test_support.h"

namespace kestrel::planner {
namespace {

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }


TEST(RosMap, GridIsTheImageFlippedWithThresholdsApplied) {
  kestrel::test::TempDir dir;
  cv::Mat img(4, 6, CV_8UC1, cv::Scalar(254));  // free
  img.at<uint8_t>(0, 0) = 0;                     // top-left: occupied
  img.at<uint8_t>(3, 5) = 205;                   // bottom-right: unknown (p = 0.2)
  image::write_png((dir / "m.png").string(), img);
  write(dir / "m.yaml", "image: m.png\nresolution: 0.5\norigin: [1.0, 2.0, 0.0]\nnegate: 0\n"
                        "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  const OccupancyGrid g = read_ros_map((dir / "m.yaml").string());
  ASSERT_EQ(g.width, 6);
  ASSERT_EQ(g.height, 4);
  EXPECT_EQ(g.at(0, 3), OccupancyGrid::kOccupied);  // the image's top row is the grid's last
  EXPECT_EQ(g.at(5, 0), OccupancyGrid::kUnknown);
  EXPECT_EQ(g.at(2, 2), OccupancyGrid::kFree);
  // The lower-left pixel's centre sits half a cell inside the origin.
  const Eigen::Vector2d p = g.T_world_grid * Eigen::Vector2d(0, 0);
  EXPECT_NEAR(p.x(), 1.25, 1e-9);
  EXPECT_NEAR(p.y(), 2.25, 1e-9);
}

TEST(RosMap, MalformedFilesGiveErrorsNamingTheFile) {
  kestrel::test::TempDir dir;
  const std::string missing = (dir / "missing.yaml").string();
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(missing); }).find(missing), std::string::npos);
  const std::string bad = (dir / "bad.yaml").string();
  write(bad, "image: m.png\nresolution: [oops\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(bad); }).find(bad), std::string::npos);
  const std::string no_image = (dir / "noimage.yaml").string();
  write(no_image, "image: none.png\nresolution: 0.1\norigin: [0, 0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(no_image); }).find("noimage.yaml"), std::string::npos);
  const std::string nan = (dir / "nan.yaml").string();
  write(nan, "image: m.png\nresolution: -1\norigin: [0, 0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(nan); }).find(nan), std::string::npos);
}

TEST(RosMap, SizesAreBoundedBeforeTheGridIsMade) {
  // The planner's grid comes from the sim's reader, whose bounds it relies on (occupancy_map.h).
  kestrel::test::TempDir dir;
  image::write_png((dir / "m.png").string(), cv::Mat(4, 6, CV_8UC1, cv::Scalar(254)));
  const std::string coarse = (dir / "coarse.yaml").string();
  write(coarse, "image: m.png\nresolution: 1000\norigin: [0, 0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(coarse); }).find(coarse + ":2: 'resolution' must be in"), std::string::npos)
      << kestrel::test::input_error_of([&] { read_ros_map(coarse); });
  const std::string far = (dir / "far.yaml").string();
  write(far, "image: m.png\nresolution: 0.05\norigin: [0, 1e15, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_ros_map(far); }).find(far + ":3: 'origin'"), std::string::npos);
  const std::string fine = (dir / "fine.yaml").string();
  write(fine, "image: m.png\nresolution: 10\norigin: [0, 0, 0]\n");
  EXPECT_EQ(read_ros_map(fine).width, 6);
}

TEST(OctoMap, ProjectsTheHeightBandOntoTheGrid) {
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(1.05f, 1.05f, 1.05f), true);    // in the band: a wall
  tree.updateNode(octomap::point3d(2.05f, 1.05f, 1.05f), false);   // in the band: seen free
  tree.updateNode(octomap::point3d(3.05f, 1.05f, 5.05f), true);    // above the band
  tree.updateNode(octomap::point3d(3.05f, 1.05f, 1.05f), false);   // ... with free space below it
  tree.updateNode(octomap::point3d(0.05f, 0.05f, 1.05f), false);   // extent
  const OccupancyGrid g = project_octomap(tree, 0.5, 2.0, "test");
  const GridEnvironment env(g, 0.5, 2.0);
  const auto cell = [&](double x, double y) {
    const Eigen::Vector2d c = g.T_world_grid.inverse() * Eigen::Vector2d(x, y);
    return g.at(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())));
  };
  EXPECT_EQ(cell(1.05, 1.05), OccupancyGrid::kOccupied);
  EXPECT_EQ(cell(2.05, 1.05), OccupancyGrid::kFree);
  EXPECT_EQ(cell(3.05, 1.05), OccupancyGrid::kFree);
  EXPECT_EQ(cell(1.55, 1.05), OccupancyGrid::kUnknown);  // never observed
}

// MAP_OCTOMAP streams are read through the mapper's checked reader (the planner process does):
// junk, and a stream whose nodes claim children 200,000 levels deep -- on which OctoMap's own
// readBinary recurses until the stack overflows (a 400 kB message crashed the planner
// before) -- are errors naming the source.
TEST(OctoMap, CorruptStreamsAndEmptyTreesAreErrorsNamingTheSource) {
  using mapper::OctreeFormat;
  const std::vector<uint8_t> junk{1, 2, 3, 4, 5};
  for (const OctreeFormat format : {OctreeFormat::kBinary, OctreeFormat::kFull})
    EXPECT_NE(kestrel::test::input_error_of([&] { mapper::read_octree(junk.data(), junk.size(), format, "MAP_OCTOMAP"); }).find("MAP_OCTOMAP"),
              std::string::npos);
  std::string deep = "# Octomap OcTree binary file\nid OcTree\nsize 40\nres 0.1\ndata\n";
  for (int i = 0; i < 200000; ++i) deep += std::string("\x03\x00", 2);  // child 0 an inner node, again and again
  const auto* bytes = reinterpret_cast<const uint8_t*>(deep.data());
  EXPECT_NE(kestrel::test::input_error_of([&] { mapper::read_octree(bytes, deep.size(), OctreeFormat::kBinary, "MAP_OCTOMAP"); })
                .find("MAP_OCTOMAP"),
            std::string::npos);
  octomap::OcTree empty(0.1);
  EXPECT_NE(kestrel::test::input_error_of([&] { project_octomap(empty, 0.0, 1.0, "MAP_OCTOMAP"); }).find("MAP_OCTOMAP"), std::string::npos);
  // A real stream round-trips.
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(1.0f, 1.0f, 1.0f), true);
  std::ostringstream out;
  tree.writeBinary(out);
  const std::string s = out.str();
  const auto back = mapper::read_octree(reinterpret_cast<const uint8_t*>(s.data()), s.size(),
                                       mapper::OctreeFormat::kBinary, "MAP_OCTOMAP");
  EXPECT_EQ(back->size(), tree.size());
}

}  // namespace
}  // namespace kestrel::planner
