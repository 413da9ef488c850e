// MAP_OCTOMAP as ROS messages (ros/map_convert.h) on hand-made OcTrees: the exact cell centres
// (a pruned block stands for each of its cells), the PointCloud2's layout, the CUBE_LIST, and
// bag-export writing them from a log; a damaged map is an InputError naming it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <sstream>

#include <octomap/OcTree.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "ros/bag_export.h"
#include "ros/map_convert.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

using Points = std::vector<std::array<float, 3>>;

constexpr double kRes = 0.1;

Points sorted(const std::vector<Eigen::Vector3f>& v) {
  Points p;
  for (const auto& x : v) p.push_back({x.x(), x.y(), x.z()});
  std::sort(p.begin(), p.end());
  return p;
}

Points sorted(Points p) {
  std::sort(p.begin(), p.end());
  return p;
}

// The centre of the cell of `kRes` with integer index (i, j, k): OctoMap's cells are centred at
// (index + 1/2) * resolution, the origin on a cell corner.
std::array<float, 3> centre(int i, int j, int k) {
  return {static_cast<float>((i + 0.5) * kRes), static_cast<float>((j + 0.5) * kRes), static_cast<float>((k + 0.5) * kRes)};
}

kestrel::octomap_t message_of(octomap::OcTree& tree, bool binary) {
  std::stringstream s;
  if (binary) {
    tree.writeBinary(s);
  } else {
    tree.write(s);
  }
  const std::string bytes = s.str();
  kestrel::octomap_t m{};
  m.utime = 2000000;
  m.revision = 1;
  m.resolution = kRes;
  m.format = binary ? kestrel::octomap_t::FORMAT_BINARY : kestrel::octomap_t::FORMAT_FULL;
  m.data.assign(bytes.begin(), bytes.end());
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

// Occupied: two single cells, one of them at negative coordinates, and a 2x2x2 block aligned on
// its parent (OctoMap prunes it into one leaf of 0.2 m); free: one cell.
octomap::OcTree hand_made_tree() {
  octomap::OcTree tree(kRes);
  auto set = [&](int i, int j, int k, bool occupied) {
    const auto c = centre(i, j, k);
    for (int n = 0; n < 10; ++n) tree.updateNode(octomap::point3d(c[0], c[1], c[2]), occupied);
  };
  set(3, 1, 0, true);
  set(-2, 5, 7, true);
  for (int i = 4; i < 6; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 2; k < 4; ++k) set(i, j, k, true);
  set(0, 0, 0, false);
  tree.updateInnerOccupancy();
  tree.prune();
  return tree;
}

Points expected_occupied() {
  Points p = {centre(3, 1, 0), centre(-2, 5, 7)};
  for (int i = 4; i < 6; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 2; k < 4; ++k) p.push_back(centre(i, j, k));
  return sorted(p);
}

TEST(MapConvert, OccupiedCellCentresAreExactAndAPrunedBlockGivesEachCell) {
  octomap::OcTree tree = hand_made_tree();
  // The block is one leaf of twice the resolution: the expansion is what is tested.
  size_t big_leaves = 0;
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it)
    if (it.getSize() > 1.5 * kRes) ++big_leaves;
  ASSERT_EQ(big_leaves, 1u);
  for (const bool binary : {true, false}) {
    const ros1::MapCells cells = ros1::map_cells(message_of(tree, binary), true, "MAP_OCTOMAP");
    EXPECT_EQ(cells.resolution_m, kRes);
    EXPECT_EQ(sorted(cells.occupied), expected_occupied()) << (binary ? "binary" : "full");
    EXPECT_EQ(sorted(cells.free), sorted(Points{centre(0, 0, 0)}));
    EXPECT_TRUE(ros1::map_cells(message_of(tree, binary), false, "MAP_OCTOMAP").free.empty());
  }
}

TEST(MapConvert, PointCloudIsFloat32XyzOfThePoints) {
  const std::vector<Eigen::Vector3f> points = {{0.05f, 0.15f, -0.25f}, {1.5f, -2.5f, 3.25f}};
  const sensor_msgs::PointCloud2 c = ros1::point_cloud(points, "map", ros::Time(2, 5000));
  EXPECT_EQ(c.header.frame_id, "map");
  EXPECT_EQ(c.header.stamp, ros::Time(2, 5000));
  EXPECT_EQ(c.height, 1u);
  EXPECT_EQ(c.width, 2u);
  EXPECT_EQ(c.point_step, 12u);
  EXPECT_EQ(c.row_step, 24u);
  EXPECT_TRUE(c.is_dense);
  EXPECT_FALSE(c.is_bigendian);
  ASSERT_EQ(c.fields.size(), 3u);
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(c.fields[i].name, std::string(1, "xyz"[i]));
    EXPECT_EQ(c.fields[i].offset, 4 * i);
    EXPECT_EQ(c.fields[i].datatype, sensor_msgs::PointField::FLOAT32);
    EXPECT_EQ(c.fields[i].count, 1u);
  }
  ASSERT_EQ(c.data.size(), 24u);
  float xyz[6];
  std::memcpy(xyz, c.data.data(), 24);
  EXPECT_EQ(xyz[0], 0.05f);
  EXPECT_EQ(xyz[2], -0.25f);
  EXPECT_EQ(xyz[4], -2.5f);
  EXPECT_EQ(xyz[5], 3.25f);
}

TEST(MapConvert, VoxelsAreOneCubeListOfTheResolutionAndAnEmptyMapClearsThem) {
  ros1::MapCells cells;
  cells.resolution_m = kRes;
  cells.occupied = {{0.05f, 0.05f, 0.05f}, {0.05f, 0.05f, 1.05f}};
  const auto a = ros1::voxel_markers(cells, "map", ros::Time(3, 0));
  ASSERT_EQ(a.markers.size(), 1u);
  const auto& m = a.markers[0];
  EXPECT_EQ(m.type, visualization_msgs::Marker::CUBE_LIST);
  EXPECT_EQ(m.action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(m.header.frame_id, "map");
  EXPECT_EQ(m.scale.x, kRes);
  EXPECT_EQ(m.scale.z, kRes);
  EXPECT_EQ(m.pose.orientation.w, 1.0);
  ASSERT_EQ(m.points.size(), 2u);
  ASSERT_EQ(m.colors.size(), 2u);
  EXPECT_FLOAT_EQ(m.points[1].z, 1.05f);
  EXPECT_EQ(m.colors[0].b, 1.0f);  // the lowest blue, the highest red
  EXPECT_EQ(m.colors[1].r, 1.0f);
  const auto cleared = ros1::voxel_markers(ros1::MapCells{kRes, {}, {}}, "map", ros::Time(3, 0));
  ASSERT_EQ(cleared.markers.size(), 1u);
  EXPECT_EQ(cleared.markers[0].action, visualization_msgs::Marker::DELETEALL);
}

TEST(MapConvert, ADamagedMapIsAnInputErrorNamingIt) {
  octomap::OcTree tree = hand_made_tree();
  kestrel::octomap_t m = message_of(tree, true);
  m.data.resize(m.data.size() / 2);
  m.size = static_cast<int32_t>(m.data.size());
  EXPECT_NE(test::input_error_of([&] { ros1::map_cells(m, false, "log: MAP_OCTOMAP event 7"); }).find("log: MAP_OCTOMAP event 7"),
            std::string::npos);
  m = message_of(tree, true);
  m.format = 9;
  EXPECT_NE(test::input_error_of([&] { ros1::map_cells(m, false, "MAP_OCTOMAP"); }).find("unknown map format 9"),
            std::string::npos);
}

TEST(MapConvert, BagExportWritesTheMapsCellsAndVoxels) {
  test::TempDir dir;
  octomap::OcTree tree = hand_made_tree();
  {
    transport::LogWriter log((dir / "map.lcmlog").string());
    const kestrel::octomap_t m = message_of(tree, true);
    log.write(channel::kMapOctomap, m.utime, transport::encode_message(m));
  }
  ros1::BagExportOptions o;
  o.map_free = true;
  {
    rosbag::Bag bag((dir / "map.bag").string(), rosbag::bagmode::Write);
    const auto stats = ros1::export_log((dir / "map.lcmlog").string(), o, bag);
    EXPECT_EQ(stats.messages.at("/kestrel/map/occupied"), 1);
    EXPECT_EQ(stats.messages.at("/kestrel/map/free"), 1);
    EXPECT_EQ(stats.messages.at("/kestrel/map/voxels"), 1);
  }
  rosbag::Bag bag((dir / "map.bag").string(), rosbag::bagmode::Read);
  size_t clouds = 0;
  for (const rosbag::MessageInstance& i : rosbag::View(bag, rosbag::TopicQuery("/kestrel/map/occupied"))) {
    const auto c = i.instantiate<sensor_msgs::PointCloud2>();
    ASSERT_TRUE(c);
    EXPECT_EQ(c->header.stamp, ros::Time(2, 0));
    EXPECT_EQ(c->header.frame_id, "map");
    Points got(c->width);
    ASSERT_EQ(c->data.size(), 12u * c->width);
    std::memcpy(got.data(), c->data.data(), c->data.size());
    EXPECT_EQ(sorted(got), expected_occupied());
    ++clouds;
  }
  EXPECT_EQ(clouds, 1u);
  for (const rosbag::MessageInstance& i : rosbag::View(bag, rosbag::TopicQuery("/kestrel/map/voxels"))) {
    const auto a = i.instantiate<visualization_msgs::MarkerArray>();
    ASSERT_TRUE(a);
    ASSERT_EQ(a->markers.size(), 1u);
    EXPECT_EQ(a->markers[0].points.size(), expected_occupied().size());
  }
}

}  // namespace
}  // namespace kestrel
