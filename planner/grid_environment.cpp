// GridEnvironment: clearance by a distance transform, segments by dense sampling, line of
// sight by walking the cells (Amanatides-Woo).
#include "planner/grid_environment.h"

#include "common/numbers.h"

#include <opencv2/imgproc.hpp>
#include <cmath>
#include <stdexcept>

namespace kestrel::planner {

OccupancyGrid make_grid(int width, int height, double resolution, double x0, double y0) {
  OccupancyGrid g;
  g.width = width;
  g.height = height;
  g.resolution = resolution;
  g.T_world_grid = Eigen::Translation2d(x0, y0) * Eigen::Scaling(resolution);
  g.cells.assign(static_cast<size_t>(width) * height, OccupancyGrid::kFree);
  return g;
}

void fill_rect(OccupancyGrid& grid, double x0, double y0, double x1, double y1, uint8_t value) {
  for (int r = 0; r < grid.height; ++r)
    for (int c = 0; c < grid.width; ++c) {
      const Eigen::Vector2d p = grid.T_world_grid * Eigen::Vector2d(c, r);
      if (p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1)
        grid.cells[static_cast<size_t>(r) * grid.width + c] = value;
    }
}

GridEnvironment::GridEnvironment(OccupancyGrid grid, double z_min, double z_max)
    : grid_(std::move(grid)), z_min_(z_min), z_max_(z_max) {
  if (grid_.width <= 0 || grid_.height <= 0 ||
      grid_.cells.size() != static_cast<size_t>(grid_.width) * grid_.height)
    throw std::invalid_argument("GridEnvironment: empty or inconsistent grid");
  if (!(z_max > z_min)) throw std::invalid_argument("GridEnvironment: z_max must exceed z_min");
  T_grid_world_ = grid_.T_world_grid.inverse();
  // Distance of every cell centre to the nearest non-free cell centre (cells, exact L2). The
  // mask has a one-cell border of non-free cells: beyond the map is unknown, hence blocked.
  cv::Mat free_mask(grid_.height + 2, grid_.width + 2, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < grid_.height; ++r)
    for (int c = 0; c < grid_.width; ++c)
      free_mask.at<uint8_t>(r + 1, c + 1) = grid_.at(c, r) == OccupancyGrid::kFree ? 255 : 0;
  cv::Mat dist;
  cv::distanceTransform(free_mask, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  clearance_m_.resize(grid_.cells.size());
  for (int r = 0; r < grid_.height; ++r)
    for (int c = 0; c < grid_.width; ++c) {
      const double d = static_cast<double>(dist.at<float>(r + 1, c + 1));
      clearance_m_[static_cast<size_t>(r) * grid_.width + c] =
          d <= 0.0 ? 0.f : static_cast<float>((d - 0.5) * grid_.resolution);
    }
  Eigen::AlignedBox2d box;
  for (double c : {-0.5, grid_.width - 0.5})
    for (double r : {-0.5, grid_.height - 0.5}) box.extend(grid_.T_world_grid * Eigen::Vector2d(c, r));
  bounds_ = Eigen::AlignedBox3d(Eigen::Vector3d(box.min().x(), box.min().y(), z_min),
                                Eigen::Vector3d(box.max().x(), box.max().y(), z_max));
}

bool GridEnvironment::cell_of(const Eigen::Vector2d& xy, int& col, int& row) const {
  const Eigen::Vector2d g = T_grid_world_ * xy;
  col = static_cast<int>(std::floor(g.x() + 0.5));
  row = static_cast<int>(std::floor(g.y() + 0.5));
  return col >= 0 && row >= 0 && col < grid_.width && row < grid_.height;
}

double GridEnvironment::clearance(const Eigen::Vector3d& p) const {
  int c, r;
  if (!p.allFinite() || !cell_of(p.head<2>(), c, r)) return 0.0;
  return static_cast<double>(clearance_m_[static_cast<size_t>(r) * grid_.width + c]);
}

bool GridEnvironment::is_free(const Eigen::Vector3d& p, double radius) const {
  if (!p.allFinite() || p.z() < z_min_ + radius || p.z() > z_max_ - radius) return false;
  int c, r;
  if (!cell_of(p.head<2>(), c, r) || grid_.at(c, r) != OccupancyGrid::kFree) return false;
  return static_cast<double>(clearance_m_[static_cast<size_t>(r) * grid_.width + c]) >= radius;
}

bool GridEnvironment::segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                      double radius) const {
  const double len = (b - a).norm();
  const int n = std::max(1, static_cast<int>(std::ceil(len / (0.5 * grid_.resolution))));
  for (int i = 0; i <= n; ++i)
    if (!is_free(a + (b - a) * (static_cast<double>(i) / n), radius)) return false;
  return true;
}

bool GridEnvironment::line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  // Walk the cells from a towards b; the cells within 1.5 cells of b are b's own surface.
  const Eigen::Vector2d ga = T_grid_world_ * a.head<2>(), gb = T_grid_world_ * b.head<2>();
  const Eigen::Vector2d d = gb - ga;
  const double len = d.norm();
  if (!(len > 1.5)) return true;
  const int n = static_cast<int>(std::ceil((len - 1.5) / 0.5));
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector2d g = ga + d * (std::min(0.5 * i, len - 1.5) / len);
    const int c = static_cast<int>(std::floor(g.x() + 0.5)), r = static_cast<int>(std::floor(g.y() + 0.5));
    if (c < 0 || r < 0 || c >= grid_.width || r >= grid_.height) return false;
    if (grid_.at(c, r) == OccupancyGrid::kOccupied) return false;
  }
  return true;
}

std::vector<Feature> GridEnvironment::wall_features(double density_per_m2, double wall_piece_m,
                                                    uint64_t seed) const {
  static const double kScale[4] = {0.0, 0.25, 1.0, 2.5};
  std::vector<Feature> out;
  Rng rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double area = grid_.resolution * (z_max_ - z_min_);
  const int dc[4] = {1, -1, 0, 0}, dr[4] = {0, 0, 1, -1};
  for (int r = 0; r < grid_.height; ++r)
    for (int c = 0; c < grid_.width; ++c) {
      if (grid_.at(c, r) != OccupancyGrid::kOccupied) continue;
      const Eigen::Vector2d centre = grid_.T_world_grid * Eigen::Vector2d(c, r);
      // The wall piece's texture class: a hash of the piece's index, so it is stable per seed.
      const auto px = static_cast<int64_t>(std::floor(centre.x() / wall_piece_m));
      const auto py = static_cast<int64_t>(std::floor(centre.y() / wall_piece_m));
      const uint64_t h = (static_cast<uint64_t>(px) * 0x9E3779B97F4A7C15ull) ^
                         (static_cast<uint64_t>(py) * 0xC2B2AE3D27D4EB4Full) ^ seed;
      const double scale = kScale[(h >> 29) % 4];
      for (int k = 0; k < 4; ++k) {
        const int c2 = c + dc[k], r2 = r + dr[k];
        if (c2 < 0 || r2 < 0 || c2 >= grid_.width || r2 >= grid_.height) continue;
        if (grid_.at(c2, r2) != OccupancyGrid::kFree) continue;
        std::poisson_distribution<int> count(density_per_m2 * scale * area);
        const Eigen::Vector2d face = grid_.T_world_grid * Eigen::Vector2d(c + 0.5 * dc[k], r + 0.5 * dr[k]);
        const Eigen::Vector2d along = grid_.T_world_grid.linear() * Eigen::Vector2d(dr[k], dc[k]);
        const Eigen::Vector2d normal = (face - centre).normalized();
        for (int i = count(rng); i > 0; --i) {
          Feature f;
          const Eigen::Vector2d xy = face + (u01(rng) - 0.5) * along;
          f.position = Eigen::Vector3d(xy.x(), xy.y(), z_min_ + u01(rng) * (z_max_ - z_min_));
          f.normal = Eigen::Vector3d(normal.x(), normal.y(), 0.0);
          out.push_back(f);
        }
      }
    }
  return out;
}

}  // namespace kestrel::planner
