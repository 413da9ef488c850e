// The station's map: occupied cells of a known map, the difference between two maps, the
// binary message the page reads, and the checks on corrupt input.
#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "common/error.h"
#include "mapper/octree_io.h"
#include "station/map_cells.h"
#include "station/wire.h"

namespace kestrel::station {
namespace {

mapper::VoxelMap map_with(const std::vector<Eigen::Vector3d>& occupied, const std::vector<Eigen::Vector3d>& free_cells,
                          double resolution = 0.1) {
  mapper::MapOptions o;
  o.resolution_m = resolution;
  mapper::VoxelMap map(o);
  for (const auto& p : occupied) {
    mapper::Key k;
    EXPECT_TRUE(map.keys().key(p.x(), p.y(), p.z(), k));
    map.set(k, 2.0f);
  }
  for (const auto& p : free_cells) {
    mapper::Key k;
    EXPECT_TRUE(map.keys().key(p.x(), p.y(), p.z(), k));
    map.set(k, -2.0f);
  }
  return map;
}

using CellTuple = std::tuple<float, float, float, float>;
std::set<CellTuple> as_set(const std::vector<Cell>& cells) {
  std::set<CellTuple> s;
  for (const Cell& c : cells) s.insert({c.x, c.y, c.z, c.size});
  return s;
}

TEST(StationMapCells, OccupiedCellsAreTheMapsWithTheirCentresAndKnownBounds) {
  const auto map = map_with({{0.01, 0.02, 1.03}, {-0.45, 0.3, 0.2}}, {{2.05, -1.0, 0.5}});
  const CellSet cells = occupied_cells(map, 7);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells.revision, 7);
  EXPECT_DOUBLE_EQ(cells.resolution_m, 0.1);
  // Cell k covers [k * 0.1, (k + 1) * 0.1): the centres are the middles.
  EXPECT_EQ(as_set(cells.cells), (std::set<CellTuple>{{0.05f, 0.05f, 1.05f, 0.1f}, {-0.45f, 0.35f, 0.25f, 0.1f}}));
  EXPECT_NEAR(cells.known_bounds.min().x(), -0.5, 1e-9);
  EXPECT_NEAR(cells.known_bounds.max().x(), 2.1, 1e-9);
  EXPECT_NEAR(cells.known_bounds.min().y(), -1.0, 1e-9);
  EXPECT_NEAR(cells.known_bounds.max().z(), 1.1, 1e-9);
  EXPECT_TRUE(std::is_sorted(cells.ids.begin(), cells.ids.end()));
  EXPECT_TRUE(cells.occupied_at({0.09, 0.01, 1.0}));
  EXPECT_FALSE(cells.occupied_at({2.05, -1.0, 0.5}));  // free
  EXPECT_FALSE(cells.occupied_at({5.0, 5.0, 5.0}));    // unknown
}

TEST(StationMapCells, ClearanceIsTheDistanceToTheNearestOccupiedCube) {
  const CellSet cells = occupied_cells(map_with({{1.05, 0.05, 1.05}}, {}), 1);
  // The cube spans x in [1.0, 1.1): a point at x = 1.25 is 0.15 m from it.
  EXPECT_TRUE(cells.occupied_within({1.25, 0.05, 1.05}, 0.2));
  EXPECT_FALSE(cells.occupied_within({1.25, 0.05, 1.05}, 0.1));
  EXPECT_TRUE(cells.occupied_within({1.05, 0.05, 1.05}, 0.0));
}

TEST(StationMapCells, TheMessagesCellCountIsTheMappersOccupiedCount) {
  std::vector<Eigen::Vector3d> occupied;
  for (int i = 0; i < 50; ++i) occupied.push_back({0.1 * i, 0.05 * (i % 7), 0.3 + 0.1 * (i % 3)});
  const auto map = map_with(occupied, {{-1.0, -1.0, 0.0}, {3.0, 2.0, 2.0}});
  kestrel::octomap_t msg{};
  msg.revision = 3;
  msg.resolution = map.resolution();
  msg.format = kestrel::octomap_t::FORMAT_BINARY;
  msg.data = mapper::encode_octree(map, mapper::OctreeFormat::kBinary);
  msg.size = static_cast<int32_t>(msg.data.size());
  const CellSet cells = cells_of_message(msg, "MAP_OCTOMAP");
  const auto decoded = mapper::decode_octree(msg.data.data(), msg.data.size(), mapper::OctreeFormat::kBinary, "x");
  EXPECT_EQ(cells.size(), decoded.num_occupied());
  EXPECT_EQ(cells.size(), map.num_occupied());
  EXPECT_EQ(as_set(cells.cells), as_set(occupied_cells(map, 3).cells));
}

TEST(StationMapCells, ACorruptMessageIsAnInputErrorNamingTheChannel) {
  kestrel::octomap_t msg{};
  msg.format = kestrel::octomap_t::FORMAT_BINARY;
  msg.data = {1, 2, 3, 4, 5, 6, 7, 8};
  msg.size = 8;
  try {
    cells_of_message(msg, "MAP_OCTOMAP");
    FAIL() << "garbage decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("MAP_OCTOMAP"), std::string::npos) << e.what();
  }
  msg.size = 9;  // disagrees with the data
  EXPECT_THROW(cells_of_message(msg, "MAP_OCTOMAP"), InputError);
  msg.size = 8;
  msg.format = 5;
  EXPECT_THROW(cells_of_message(msg, "MAP_OCTOMAP"), InputError);
}

TEST(StationMapCells, TheDifferenceTurnsOneMapIntoTheOther) {
  const CellSet before = occupied_cells(map_with({{0.05, 0.05, 0.05}, {0.15, 0.05, 0.05}, {0.25, 0.05, 0.05}}, {}), 1);
  const CellSet after = occupied_cells(map_with({{0.15, 0.05, 0.05}, {0.25, 0.05, 0.05}, {0.95, 0.95, 0.95}}, {}), 2);
  const CellDiff d = diff_cells(before, after);
  EXPECT_FALSE(d.reset);
  EXPECT_EQ(as_set(d.added), (std::set<CellTuple>{{0.95f, 0.95f, 0.95f, 0.1f}}));
  EXPECT_EQ(as_set(d.removed), (std::set<CellTuple>{{0.05f, 0.05f, 0.05f, 0.1f}}));
  // Applied to `before`, it gives `after`.
  std::set<CellTuple> page = as_set(before.cells);
  for (const Cell& c : d.removed) page.erase({c.x, c.y, c.z, c.size});
  for (const Cell& c : d.added) page.insert({c.x, c.y, c.z, c.size});
  EXPECT_EQ(page, as_set(after.cells));
  EXPECT_TRUE(diff_cells(after, after).empty());
}

TEST(StationMapCells, ANewResolutionOrAFirstMapIsAReset) {
  const CellSet fine = occupied_cells(map_with({{0.05, 0.05, 0.05}}, {}, 0.05), 1);
  const CellSet coarse = occupied_cells(map_with({{0.05, 0.05, 0.05}, {0.5, 0.5, 0.5}}, {}, 0.1), 2);
  const CellDiff d = diff_cells(fine, coarse);
  EXPECT_TRUE(d.reset);
  EXPECT_EQ(d.added.size(), 2u);
  EXPECT_TRUE(d.removed.empty());
  EXPECT_TRUE(diff_cells(CellSet{}, coarse).reset);
}

TEST(StationWire, AMapMessageReadsBackAsWritten) {
  CellDiff d;
  d.reset = true;
  d.added = {{1.f, 2.f, 3.f, 0.1f}, {-1.f, 0.5f, 2.f, 0.1f}};
  d.removed = {{4.f, 5.f, 6.f, 0.1f}};
  const std::string m = encode_map_diff(d, 2);
  EXPECT_EQ(m.size(), kMapHeaderBytes + 3 * kBytesPerCell);
  size_t after = 0;
  const CellDiff back = decode_map_diff(m, &after);
  EXPECT_TRUE(back.reset);
  EXPECT_EQ(back.added, d.added);
  EXPECT_EQ(back.removed, d.removed);
  EXPECT_EQ(after, 2u);
  EXPECT_THROW(decode_map_diff(m.substr(0, m.size() - 1)), std::invalid_argument);
  EXPECT_THROW(decode_map_diff(m + "x"), std::invalid_argument);
  EXPECT_THROW(decode_map_diff(encode_image(BinaryKind::kColour, ImageFormat::kJpeg, {1, 2})), std::invalid_argument);
}

TEST(StationWire, AnImageMessageCarriesTheFileAfterItsHeader) {
  const std::string m = encode_image(BinaryKind::kDepth, ImageFormat::kPng, {9, 8, 7});
  ASSERT_EQ(m.size(), kImageHeaderBytes + 3);
  EXPECT_EQ(static_cast<uint8_t>(m[0]), 3);
  EXPECT_EQ(static_cast<uint8_t>(m[1]), 1);
  EXPECT_EQ(static_cast<uint8_t>(m[4]), 3);  // length, little-endian
  EXPECT_EQ(m.substr(8), std::string("\x09\x08\x07"));
}

}  // namespace
}  // namespace kestrel::station
