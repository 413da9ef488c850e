#include "ros/map_convert.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <octomap/OcTree.h>

#include "common/error.h"
#include "mapper/octree_io.h"

namespace kestrel::ros1 {
namespace {

// Every cell of the finest depth inside the leaf `it`, each centre as OctoMap computes a cell's
// (keyToCoord, in double, then float): a leaf at depth d covers 2^(16-d) cells a side, and its
// key is the first of them plus half that (OcTreeKey's adjustKeyAtDepth).
void add_cells(const octomap::OcTree& tree, const octomap::OcTree::leaf_iterator& it, std::vector<Eigen::Vector3f>& out,
               const std::string& what) {
  const unsigned below = tree.getTreeDepth() - it.getDepth();
  const size_t n = size_t{1} << below;
  if (out.size() + n * n * n > kMaxCells)
    throw InputError(what + ": more than " + std::to_string(kMaxCells) + " cells of one kind (a map too large for "
                     "points at its resolution)");
  const octomap::OcTreeKey key = it.getKey();
  const unsigned half = below == 0 ? 0 : 1u << (below - 1);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      for (size_t k = 0; k < n; ++k)
        out.emplace_back(static_cast<float>(tree.keyToCoord(static_cast<octomap::key_type>(key[0] - half + i))),
                         static_cast<float>(tree.keyToCoord(static_cast<octomap::key_type>(key[1] - half + j))),
                         static_cast<float>(tree.keyToCoord(static_cast<octomap::key_type>(key[2] - half + k))));
}

}  // namespace

MapCells map_cells(const kestrel::octomap_t& m, bool with_free, const std::string& what) {
  if (m.format != kestrel::octomap_t::FORMAT_BINARY && m.format != kestrel::octomap_t::FORMAT_FULL)
    throw InputError(what + ": unknown map format " + std::to_string(m.format));
  const auto format = m.format == kestrel::octomap_t::FORMAT_BINARY ? mapper::OctreeFormat::kBinary
                                                                     : mapper::OctreeFormat::kFull;
  const auto tree = mapper::read_octree(m.data.data(), m.data.size(), format, what);
  MapCells cells;
  cells.resolution_m = tree->getResolution();
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const bool occupied = tree->isNodeOccupied(*it);
    if (!occupied && !with_free) continue;
    add_cells(*tree, it, occupied ? cells.occupied : cells.free, what);
  }
  return cells;
}

sensor_msgs::PointCloud2 point_cloud(const std::vector<Eigen::Vector3f>& points, const std::string& frame,
                                     const ros::Time& stamp) {
  sensor_msgs::PointCloud2 c;
  c.header.stamp = stamp;
  c.header.frame_id = frame;
  c.height = 1;
  c.width = static_cast<uint32_t>(points.size());
  const char* names[3] = {"x", "y", "z"};
  for (uint32_t i = 0; i < 3; ++i) {
    sensor_msgs::PointField f;
    f.name = names[i];
    f.offset = 4 * i;
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    c.fields.push_back(f);
  }
  c.is_bigendian = false;  // the floats are copied in this host's order, which is little-endian
  c.point_step = 12;
  c.row_step = c.point_step * c.width;
  c.is_dense = true;
  c.data.resize(static_cast<size_t>(c.row_step));
  for (size_t i = 0; i < points.size(); ++i) std::memcpy(c.data.data() + 12 * i, points[i].data(), 12);
  return c;
}

visualization_msgs::MarkerArray voxel_markers(const MapCells& cells, const std::string& frame, const ros::Time& stamp) {
  visualization_msgs::Marker m;
  m.header.stamp = stamp;
  m.header.frame_id = frame;
  m.ns = "occupied";
  m.id = 0;
  m.pose.orientation.w = 1.0;
  if (cells.occupied.empty()) {
    m.action = visualization_msgs::Marker::DELETEALL;
  } else {
    m.type = visualization_msgs::Marker::CUBE_LIST;
    m.action = visualization_msgs::Marker::ADD;
    m.scale.x = m.scale.y = m.scale.z = cells.resolution_m;
    m.color.a = 1.0f;
    float z_min = cells.occupied.front().z(), z_max = z_min;
    for (const auto& p : cells.occupied) {
      z_min = std::min(z_min, p.z());
      z_max = std::max(z_max, p.z());
    }
    m.points.reserve(cells.occupied.size());
    m.colors.reserve(cells.occupied.size());
    for (const auto& p : cells.occupied) {
      geometry_msgs::Point q;
      q.x = static_cast<double>(p.x());
      q.y = static_cast<double>(p.y());
      q.z = static_cast<double>(p.z());
      m.points.push_back(q);
      // Blue (low) to red (high): the cubes' height reads at a glance.
      const float h = z_max > z_min ? (p.z() - z_min) / (z_max - z_min) : 0.5f;
      std_msgs::ColorRGBA c;
      c.r = h;
      c.g = 0.3f;
      c.b = 1.0f - h;
      c.a = 1.0f;
      m.colors.push_back(c);
    }
  }
  visualization_msgs::MarkerArray a;
  a.markers.push_back(m);
  return a;
}

}  // namespace kestrel::ros1
