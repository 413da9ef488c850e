// WorldEnvironment: the sim's world behind the planner's Environment interface.
#include "planner/world_environment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "drivers/sim/collision.h"
#include "planner/types.h"

namespace kestrel::planner {

namespace {

// The last millimetre is the target's own surface: a feature on a wall sees its viewer.
constexpr double kTargetMargin_m = 1e-3;
// Slack of the fine grid's bookkeeping (obstacle boxes and the segment's cells): far above
// the rounding of a hit point (~1e-13 m in a 100 m world), so no obstacle that can be hit is
// left out; an obstacle let in by it is only tested for nothing.
constexpr double kSlack_m = 1e-5;
// The sim's CollisionIndex: 1 m cells, obstacles over more than 256 cells tested always.
constexpr double kSimCell_m = 1.0;
constexpr int kSimGlobalCells = 256;

}  // namespace

WorldEnvironment::WorldEnvironment(const sim::World& world) : world_(world) {
  // The obstacles and cell ranges exactly as sim::CollisionIndex files them (collision.cpp),
  // so that line_of_sight counts a hit only on an obstacle the sim's ray cast tests.
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const sim::Surface& s : world_.surfaces())
    if (s.box < 0) {
      Obstacle o;
      o.index = s.id;
      obstacles_.push_back(o);
      boxes.push_back(sim::bounds_of(s));
    }
  for (size_t i = 0; i < world_.boxes().size(); ++i) {
    Obstacle o;
    o.is_box = true;
    o.index = static_cast<int>(i);
    o.T_box_world = world_.boxes()[i].T_world_box.inverse();
    obstacles_.push_back(o);
    boxes.push_back(sim::bounds_of(world_.boxes()[i]));
  }
  if (obstacles_.empty()) return;
  Eigen::AlignedBox3d all;
  for (const auto& b : boxes) all.extend(b);
  sim_origin_x_ = all.min().x();
  sim_origin_y_ = all.min().y();
  sim_nx_ = std::max(1, static_cast<int>(std::ceil((all.max().x() - sim_origin_x_) / kSimCell_m)));
  sim_ny_ = std::max(1, static_cast<int>(std::ceil((all.max().y() - sim_origin_y_) / kSimCell_m)));
  for (size_t k = 0; k < obstacles_.size(); ++k) {
    Obstacle& o = obstacles_[k];
    const Eigen::AlignedBox3d& b = boxes[k];
    o.ix0 = std::clamp(static_cast<int>((b.min().x() - sim_origin_x_) / kSimCell_m), 0, sim_nx_ - 1);
    o.ix1 = std::clamp(static_cast<int>((b.max().x() - sim_origin_x_) / kSimCell_m), 0, sim_nx_ - 1);
    o.iy0 = std::clamp(static_cast<int>((b.min().y() - sim_origin_y_) / kSimCell_m), 0, sim_ny_ - 1);
    o.iy1 = std::clamp(static_cast<int>((b.max().y() - sim_origin_y_) / kSimCell_m), 0, sim_ny_ - 1);
    o.global = (o.ix1 - o.ix0 + 1) * (o.iy1 - o.iy0 + 1) > kSimGlobalCells;
    o.lo = b.min() - Eigen::Vector3d::Constant(kSlack_m);
    o.hi = b.max() + Eigen::Vector3d::Constant(kSlack_m);
    if (o.global) global_.push_back(static_cast<int>(k));
  }
  // The fine grid: every other obstacle in each cell its box (grown by the slack) meets.
  fine_origin_x_ = all.min().x() - kSlack_m;
  fine_origin_y_ = all.min().y() - kSlack_m;
  fine_nx_ = static_cast<int>(std::ceil((all.max().x() + kSlack_m - fine_origin_x_) / fine_cell_m_)) + 1;
  fine_ny_ = static_cast<int>(std::ceil((all.max().y() + kSlack_m - fine_origin_y_) / fine_cell_m_)) + 1;
  const auto cells_of = [&](const Eigen::AlignedBox3d& b, int& x0, int& x1, int& y0, int& y1) {
    x0 = std::clamp(static_cast<int>(std::floor((b.min().x() - kSlack_m - fine_origin_x_) / fine_cell_m_)), 0, fine_nx_ - 1);
    x1 = std::clamp(static_cast<int>(std::floor((b.max().x() + kSlack_m - fine_origin_x_) / fine_cell_m_)), 0, fine_nx_ - 1);
    y0 = std::clamp(static_cast<int>(std::floor((b.min().y() - kSlack_m - fine_origin_y_) / fine_cell_m_)), 0, fine_ny_ - 1);
    y1 = std::clamp(static_cast<int>(std::floor((b.max().y() + kSlack_m - fine_origin_y_) / fine_cell_m_)), 0, fine_ny_ - 1);
  };
  std::vector<int> count(static_cast<size_t>(fine_nx_) * fine_ny_ + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      fine_start_.assign(count.size(), 0);
      for (size_t c = 0; c + 1 < count.size(); ++c) fine_start_[c + 1] = fine_start_[c] + count[c];
      fine_items_.assign(static_cast<size_t>(fine_start_.back()), -1);
      std::fill(count.begin(), count.end(), 0);
    }
    for (size_t k = 0; k < obstacles_.size(); ++k) {
      if (obstacles_[k].global) continue;
      int x0, x1, y0, y1;
      cells_of(boxes[k], x0, x1, y0, y1);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t c = static_cast<size_t>(y) * fine_nx_ + x;
          if (pass == 1) fine_items_[static_cast<size_t>(fine_start_[c] + count[c])] = static_cast<int>(k);
          ++count[c];
        }
    }
  }
}

bool WorldEnvironment::hits(const Obstacle& o, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                            double max_distance) const {
  // The sim's own ray tests (drivers/sim/collision.h), the box's inverse pose kept per
  // obstacle, then the sim's acceptance: a hit no farther than max_distance.
  if (!o.is_box) return sim::ray_rectangle(origin, dir, world_.surfaces()[o.index]) <= max_distance;
  int axis = -1;
  return sim::ray_box_local(o.T_box_world * origin, o.T_box_world.linear() * dir,
                            world_.boxes()[o.index].half_extent, &axis) <= max_distance;
}

bool WorldEnvironment::sim_tests(const Obstacle& o, const Eigen::Vector3d& a, const Eigen::Vector3d& end) const {
  if (o.global) return true;
  const Eigen::Vector3d lo = a.cwiseMin(end), hi = a.cwiseMax(end);
  const int qx0 = std::clamp(static_cast<int>(std::floor((lo.x() - sim_origin_x_) / kSimCell_m)), 0, sim_nx_ - 1);
  const int qx1 = std::clamp(static_cast<int>(std::floor((hi.x() - sim_origin_x_) / kSimCell_m)), 0, sim_nx_ - 1);
  const int qy0 = std::clamp(static_cast<int>(std::floor((lo.y() - sim_origin_y_) / kSimCell_m)), 0, sim_ny_ - 1);
  const int qy1 = std::clamp(static_cast<int>(std::floor((hi.y() - sim_origin_y_) / kSimCell_m)), 0, sim_ny_ - 1);
  return !(o.ix0 > qx1 || o.ix1 < qx0 || o.iy0 > qy1 || o.iy1 < qy0);
}

void WorldEnvironment::lines_of_sight(const Eigen::Vector3d& a, const std::vector<Eigen::Vector3d>& targets,
                                      std::vector<char>& out) const {
  out.assign(targets.size(), 1);
  if (obstacles_.empty() || targets.empty()) return;
  // The obstacles whose box meets the box of every target around a (with slack).
  Eigen::AlignedBox3d reach(a);
  for (const Eigen::Vector3d& b : targets) reach.extend(b);
  reach.min() -= Eigen::Vector3d::Constant(kSlack_m);
  reach.max() += Eigen::Vector3d::Constant(kSlack_m);
  thread_local std::vector<uint32_t> stamp;
  thread_local uint32_t query = 0;
  thread_local std::vector<int> near;
  if (stamp.size() < obstacles_.size()) stamp.resize(obstacles_.size(), 0);
  if (++query == 0) {
    std::fill(stamp.begin(), stamp.end(), 0);
    query = 1;
  }
  near.clear();
  const auto take = [&](int k) {
    const Obstacle& o = obstacles_[static_cast<size_t>(k)];
    if ((o.lo.array() <= reach.max().array()).all() && (o.hi.array() >= reach.min().array()).all()) near.push_back(k);
  };
  for (int k : global_) take(k);
  const auto cell = [&](double v, double origin, int n) {
    return std::clamp(static_cast<int>(std::floor((v - origin) / fine_cell_m_)), 0, n - 1);
  };
  const int x0 = cell(reach.min().x(), fine_origin_x_, fine_nx_), x1 = cell(reach.max().x(), fine_origin_x_, fine_nx_);
  const int y0 = cell(reach.min().y(), fine_origin_y_, fine_ny_), y1 = cell(reach.max().y(), fine_origin_y_, fine_ny_);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const size_t c = static_cast<size_t>(y) * fine_nx_ + x;
      for (int j = fine_start_[c]; j < fine_start_[c + 1]; ++j) {
        const int k = fine_items_[static_cast<size_t>(j)];
        if (stamp[static_cast<size_t>(k)] == query) continue;
        stamp[static_cast<size_t>(k)] = query;
        take(k);
      }
    }
  // Each ray: the same direction, length and end as line_of_sight_by_raycast; an obstacle
  // blocks when its box meets the ray's, the sim's ray test hits it within the length, and
  // the sim's ray cast would have tested it.
  for (size_t i = 0; i < targets.size(); ++i) {
    const Eigen::Vector3d d = targets[i] - a;
    const double length = d.norm();
    if (length <= kTargetMargin_m) continue;
    const Eigen::Vector3d dir = d / length;
    const double max_distance = length - kTargetMargin_m;
    const Eigen::Vector3d end = a + max_distance * dir;
    const Eigen::Vector3d lo = a.cwiseMin(end), hi = a.cwiseMax(end);
    for (int k : near) {
      const Obstacle& o = obstacles_[static_cast<size_t>(k)];
      if ((o.lo.array() > hi.array()).any() || (o.hi.array() < lo.array()).any()) continue;
      if (hits(o, a, dir, max_distance) && sim_tests(o, a, end)) {
        out[i] = 0;
        break;
      }
    }
  }
}

bool WorldEnvironment::line_of_sight_by_raycast(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  if (length <= kTargetMargin_m) return true;
  return !world_.raycast(a, d / length, length - kTargetMargin_m).has_value();
}

bool WorldEnvironment::line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  if (length <= kTargetMargin_m) return true;
  if (obstacles_.empty()) return true;
  const Eigen::Vector3d dir = d / length;
  const double max_distance = length - kTargetMargin_m;
  // The cells the sim's ray cast gathers obstacles from: those of the ray's bounding box.
  const Eigen::Vector3d end = a + max_distance * dir;
  const Eigen::Vector3d lo = a.cwiseMin(end), hi = a.cwiseMax(end);
  const int qx0 = std::clamp(static_cast<int>(std::floor((lo.x() - sim_origin_x_) / kSimCell_m)), 0, sim_nx_ - 1);
  const int qx1 = std::clamp(static_cast<int>(std::floor((hi.x() - sim_origin_x_) / kSimCell_m)), 0, sim_nx_ - 1);
  const int qy0 = std::clamp(static_cast<int>(std::floor((lo.y() - sim_origin_y_) / kSimCell_m)), 0, sim_ny_ - 1);
  const int qy1 = std::clamp(static_cast<int>(std::floor((hi.y() - sim_origin_y_) / kSimCell_m)), 0, sim_ny_ - 1);
  const auto blocks = [&](int k) {
    const Obstacle& o = obstacles_[k];
    if (!o.global && (o.ix0 > qx1 || o.ix1 < qx0 || o.iy0 > qy1 || o.iy1 < qy0)) return false;
    return hits(o, a, dir, max_distance);
  };
  for (int k : global_)
    if (blocks(k)) return false;
  // Walk the fine cells the segment a -> end passes (each column's span of y, with slack);
  // an obstacle met in several cells is tested once (a per-thread stamp per obstacle).
  thread_local std::vector<uint32_t> stamp;
  thread_local uint32_t query = 0;
  if (stamp.size() < obstacles_.size()) stamp.resize(obstacles_.size(), 0);
  if (++query == 0) {  // wrapped round: forget every stamp
    std::fill(stamp.begin(), stamp.end(), 0);
    query = 1;
  }
  const double xa = a.x(), ya = a.y(), xb = end.x(), yb = end.y();
  const double x_min = std::min(xa, xb), x_max = std::max(xa, xb);
  const bool steep = x_max - x_min < 1e-3;  // one or two columns: take the whole y span
  const int cx0 = std::clamp(static_cast<int>(std::floor((x_min - kSlack_m - fine_origin_x_) / fine_cell_m_)), 0, fine_nx_ - 1);
  const int cx1 = std::clamp(static_cast<int>(std::floor((x_max + kSlack_m - fine_origin_x_) / fine_cell_m_)), 0, fine_nx_ - 1);
  for (int cx = cx0; cx <= cx1; ++cx) {
    double y_lo = std::min(ya, yb), y_hi = std::max(ya, yb);
    if (!steep) {
      const double x0 = std::max(x_min, fine_origin_x_ + cx * fine_cell_m_ - kSlack_m);
      const double x1 = std::min(x_max, fine_origin_x_ + (cx + 1) * fine_cell_m_ + kSlack_m);
      const double f0 = std::clamp((x0 - xa) / (xb - xa), 0.0, 1.0), f1 = std::clamp((x1 - xa) / (xb - xa), 0.0, 1.0);
      const double y0 = ya + f0 * (yb - ya), y1 = ya + f1 * (yb - ya);
      y_lo = std::min(y0, y1);
      y_hi = std::max(y0, y1);
    }
    const int cy0 = std::clamp(static_cast<int>(std::floor((y_lo - kSlack_m - fine_origin_y_) / fine_cell_m_)), 0, fine_ny_ - 1);
    const int cy1 = std::clamp(static_cast<int>(std::floor((y_hi + kSlack_m - fine_origin_y_) / fine_cell_m_)), 0, fine_ny_ - 1);
    for (int cy = cy0; cy <= cy1; ++cy) {
      const size_t c = static_cast<size_t>(cy) * fine_nx_ + cx;
      for (int j = fine_start_[c]; j < fine_start_[c + 1]; ++j) {
        const int k = fine_items_[static_cast<size_t>(j)];
        if (stamp[static_cast<size_t>(k)] == query) continue;
        stamp[static_cast<size_t>(k)] = query;
        if (blocks(k)) return false;
      }
    }
  }
  return true;
}

size_t WorldEnvironment::place_features(const WorldFeatureOptions& options) {
  if (!(options.mean_density_per_m2 >= 0.0)) throw std::invalid_argument("place_features: density must be >= 0");
  const auto& surfaces = world_.surfaces();
  double area = 0.0, weighted = 0.0;
  for (const sim::Surface& s : surfaces)
    if (s.is_vertical()) {
      area += s.area();
      weighted += world_.feature_density(s.id) * s.area();
    }
  std::vector<Feature> features;
  if (weighted > 0.0) {
    const double scale = options.mean_density_per_m2 * area / weighted;
    Rng rng(options.seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const sim::Surface& s : surfaces) {
      if (!s.is_vertical()) continue;
      const double expected = scale * world_.feature_density(s.id) * s.area();
      if (!(expected > 0.0)) continue;
      std::poisson_distribution<int> count(expected);
      for (int k = count(rng); k > 0; --k) {
        Feature f;
        f.position = s.point(u(rng) * s.width, u(rng) * s.height);
        f.normal = s.normal;
        features.push_back(f);
      }
    }
  }
  set_features(std::move(features));
  return this->features().size();
}

}  // namespace kestrel::planner
