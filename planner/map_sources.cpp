// ROS maps through the sim driver's reader; OctoMaps projected onto a grid.
#include "planner/map_sources.h"

#include <octomap/OcTree.h>

#include <cmath>

#include "common/error.h"
#include "drivers/sim/occupancy_map.h"

namespace kestrel::planner {

OccupancyGrid read_ros_map(const std::string& yaml_path) {
  const sim::OccupancyMap map = sim::read_occupancy_map(yaml_path);
  if (map.image.empty() || map.image.type() != CV_8UC1)
    throw InputError(yaml_path + ": the map image is empty or not grey");
  OccupancyGrid g;
  g.width = map.image.cols;
  g.height = map.image.rows;
  g.resolution = map.resolution;
  Eigen::Affine2d flip = Eigen::Affine2d::Identity();
  flip.matrix() << 1, 0, 0, 0, -1, g.height - 1, 0, 0, 1;  // grid (c, r) -> image (c, H - 1 - r)
  g.T_world_grid = map.T_world_pixel() * flip;
  g.cells.resize(static_cast<size_t>(g.width) * g.height);
  for (int r = 0; r < g.height; ++r)
    for (int c = 0; c < g.width; ++c) {
      const double v = map.image.at<uint8_t>(g.height - 1 - r, c);
      const double p = map.negate ? v / 255.0 : (255.0 - v) / 255.0;
      g.cells[static_cast<size_t>(r) * g.width + c] =
          p > map.occupied_thresh ? OccupancyGrid::kOccupied
                                  : (p < map.free_thresh ? OccupancyGrid::kFree : OccupancyGrid::kUnknown);
    }
  return g;
}

OccupancyGrid project_octomap(const octomap::OcTree& tree, double z_min, double z_max, const std::string& source) {
  if (tree.size() == 0) throw InputError(source + ": the OctoMap is empty");
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  const double res = tree.getResolution();
  const int w = static_cast<int>(std::ceil((x1 - x0) / res)), h = static_cast<int>(std::ceil((y1 - y0) / res));
  if (w <= 0 || h <= 0 || static_cast<double>(w) * h > 1e8) throw InputError(source + ": OctoMap extent unusable");
  OccupancyGrid g = make_grid(w, h, res, x0 + 0.5 * res, y0 + 0.5 * res);
  std::fill(g.cells.begin(), g.cells.end(), OccupancyGrid::kUnknown);
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const double size = it.getSize(), z = it.getZ();
    if (z + 0.5 * size < z_min || z - 0.5 * size > z_max) continue;
    const bool occupied = tree.isNodeOccupied(*it);
    // A coarse leaf covers several cells.
    const int c0 = static_cast<int>(std::floor((it.getX() - 0.5 * size - x0) / res + 1e-9));
    const int r0 = static_cast<int>(std::floor((it.getY() - 0.5 * size - y0) / res + 1e-9));
    const int n = std::max(1, static_cast<int>(std::lround(size / res)));
    for (int r = std::max(0, r0); r < std::min(h, r0 + n); ++r)
      for (int c = std::max(0, c0); c < std::min(w, c0 + n); ++c) {
        uint8_t& cell = g.cells[static_cast<size_t>(r) * w + c];
        if (occupied) cell = OccupancyGrid::kOccupied;
        else if (cell == OccupancyGrid::kUnknown) cell = OccupancyGrid::kFree;
      }
  }
  return g;
}

}  // namespace kestrel::planner
