#include "drivers/sim/world.h"

#include <cmath>

namespace kestrel::sim {

bool FreeMask::contains(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d px = T_pixel_world * p.head<2>();
  const double col = std::floor(px.x() + 0.5), row = std::floor(px.y() + 0.5);
  if (!(col >= 0 && row >= 0 && col < free.cols && row < free.rows)) return false;
  return free.at<uchar>(static_cast<int>(row), static_cast<int>(col)) != 0;
}

bool World::inside(const Eigen::Vector3d& p) const {
  if (!p.allFinite() || !bounds_.contains(p)) return false;
  return !free_mask_ || free_mask_->contains(p);
}

bool World::is_free(const Eigen::Vector3d& p, double radius) const {
  return inside(p) && index_.clearance(p, radius + 1e-9) > radius;
}

bool World::segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const {
  return inside(a) && inside(b) && index_.segment_clearance(a, b, radius + 1e-9) > radius;
}

}  // namespace kestrel::sim
