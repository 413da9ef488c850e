#include "drivers/sim/map_world.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "drivers/sim/random.h"
#include "drivers/sim/world_builder.h"

namespace kestrel::sim {
namespace {

// The free region that matters: spurs opened away, specks of clutter filled in, only the
// largest connected component kept.
cv::Mat clean_free_space(const cv::Mat& free, const OccupancyMap& map, const MapWorldOptions& o) {
  cv::Mat out;
  const int k = std::max(1, static_cast<int>(std::lround(o.min_passage_m / map.resolution)) | 1);
  cv::morphologyEx(free, out, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
  // Fill small holes (obstacle components that do not touch the border).
  cv::Mat solid = 255 - out, labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(solid, labels, stats, centroids, 8);
  const double min_px = o.min_obstacle_m2 / (map.resolution * map.resolution);
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < min_px) out.setTo(255, labels == i);
  }
  const int m = cv::connectedComponentsWithStats(out, labels, stats, centroids, 4);
  int best = -1, best_area = 0;
  for (int i = 1; i < m; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) > best_area) best = i, best_area = stats.at<int>(i, cv::CC_STAT_AREA);
  }
  if (best < 0) return cv::Mat::zeros(free.size(), CV_8UC1);
  cv::Mat largest = cv::Mat::zeros(free.size(), CV_8UC1);
  largest.setTo(255, labels == best);
  return largest;
}

bool free_at(const cv::Mat& free, const cv::Point2d& p) {
  const int c = static_cast<int>(std::lround(p.x)), r = static_cast<int>(std::lround(p.y));
  return c >= 0 && r >= 0 && c < free.cols && r < free.rows && free.at<uchar>(r, c) != 0;
}

// True if the free side of the closed pixel polygon lies to the left of its edges in world
// coordinates (a majority vote over the edges' midpoints).
bool free_on_left(const std::vector<cv::Point>& poly, const cv::Mat& free, const Eigen::Affine2d& T_world_pixel) {
  const double det = T_world_pixel.linear().determinant();  // < 0: the image flips handedness
  int votes = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const cv::Point2d a = poly[i], b = poly[(i + 1) % poly.size()];
    const cv::Point2d d = b - a;
    const double len = std::hypot(d.x, d.y);
    if (len < 2) continue;
    const cv::Point2d left_px(d.y / len, -d.x / len);
    const cv::Point2d mid = 0.5 * (a + b);
    const bool l = free_at(free, mid + 1.5 * left_px), r = free_at(free, mid - 1.5 * left_px);
    if (l != r) votes += l ? 1 : -1;
  }
  // left_px is the world's left when image rows run against world y (det < 0, the usual
  // case); otherwise it is the world's right.
  return det > 0 ? votes < 0 : votes > 0;
}

struct Palette {
  int blank, plaster, concrete, brick, painted_brick, poster, board, door, floor, ceiling;
};

Palette add_materials(WorldBuilder& b) {
  auto add = [&](const char* name, const char* pattern, Eigen::Vector3d color, bool fit = false) {
    MaterialSpec s;
    s.name = name;
    s.pattern = pattern;
    s.color = color;
    s.fit = fit;
    return b.add_material(s);
  };
  Palette p;
  p.blank = add("blank_paint", "plaster", {0.86, 0.85, 0.82});
  p.plaster = add("plaster", "plaster", {0.80, 0.77, 0.70});
  p.concrete = add("concrete", "concrete", {0.62, 0.61, 0.58});
  p.brick = add("brick", "brick", {0.58, 0.30, 0.22});
  p.painted_brick = add("painted_brick", "brick", {0.80, 0.80, 0.76});
  p.poster = add("posters", "poster", {0.92, 0.90, 0.85}, true);
  p.board = add("boards", "whiteboard", {0.94, 0.94, 0.93}, true);
  p.door = add("doors", "wood", {0.50, 0.33, 0.20});
  p.floor = add("floor", "floor_tiles", {0.66, 0.64, 0.60});
  p.ceiling = add("ceiling", "ceiling_tiles", {0.88, 0.88, 0.86});
  return p;
}

// One wall piece from a to b (free side on the left) with a random look, and what hangs on it.
void add_wall_piece(WorldBuilder& b, const Palette& p, const Eigen::Vector2d& a, const Eigen::Vector2d& e,
                    const MapWorldOptions& o, Rng& rng) {
  const double len = (e - a).norm();
  const double h = o.wall_height_m;
  if (rng.uniform() < o.blank_share) {
    b.add_wall(p.blank, a, e, 0.0, h, rng.uniform(0.0, 0.08));
    return;
  }
  const int choices[4] = {p.plaster, p.concrete, p.brick, p.painted_brick};
  b.add_wall(choices[rng.below(4)], a, e, 0.0, h, rng.uniform(0.45, 1.0));
  if (len < 1.5) return;
  const Eigen::Vector2d dir = (e - a) / len;
  const Eigen::Vector2d left(-dir.y(), dir.x());
  const Eigen::Vector2d off = 0.01 * left;  // hung 1 cm in front of the wall
  const int items = static_cast<int>(rng.uniform(0.0, len / 2.5));
  double at = rng.uniform(0.3, 1.0);
  for (int i = 0; i < items && at < len - 0.8; ++i) {
    const double u = rng.uniform();
    if (u < 0.55) {  // poster
      const double w = rng.uniform(0.45, 0.9), z0 = rng.uniform(1.0, 1.5);
      b.add_wall(p.poster, a + at * dir + off, a + (at + w) * dir + off, z0, z0 + rng.uniform(0.6, 1.1), 1.0, SurfaceKind::kPanel);
      at += w;
    } else if (u < 0.75) {  // board
      const double w = rng.uniform(0.9, 1.8);
      if (at + w > len - 0.2) break;
      b.add_wall(p.board, a + at * dir + off, a + (at + w) * dir + off, 0.9, 2.0, 1.0, SurfaceKind::kPanel);
      at += w;
    } else {  // door
      b.add_wall(p.door, a + at * dir + off, a + (at + 0.9) * dir + off, 0.0, 2.1, 1.0, SurfaceKind::kPanel);
      at += 0.9;
    }
    at += rng.uniform(0.5, 2.5);
  }
}

}  // namespace

World world_from_map(const OccupancyMap& map, const std::string& name, const MapWorldOptions& o) {
  const cv::Mat free = clean_free_space(map.free_mask(), map, o);
  if (cv::countNonZero(free) == 0) throw InputError(map.yaml_path + ": the map has no free space");
  const Eigen::Affine2d T_world_pixel = map.T_world_pixel();
  WorldBuilder b(name);
  b.set_source(map.yaml_path);
  b.set_seed(o.seed);
  const Palette p = add_materials(b);
  Rng rng(derive(o.seed, tag("map walls")));

  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(free.clone(), contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  Eigen::AlignedBox2d extent;
  for (const auto& contour : contours) {
    std::vector<cv::Point> poly;
    cv::approxPolyDP(contour, poly, o.simplify_m / map.resolution, true);
    if (poly.size() < 3) continue;
    if (!free_on_left(poly, free, T_world_pixel)) std::reverse(poly.begin(), poly.end());
    for (size_t i = 0; i < poly.size(); ++i) {
      const Eigen::Vector2d a = T_world_pixel * Eigen::Vector2d(poly[i].x, poly[i].y);
      const Eigen::Vector2d e = T_world_pixel * Eigen::Vector2d(poly[(i + 1) % poly.size()].x, poly[(i + 1) % poly.size()].y);
      extent.extend(a);
      const double len = (e - a).norm();
      if (len < 1e-3) continue;
      const int pieces = std::max(1, static_cast<int>(std::ceil(len / o.max_wall_piece_m)));
      for (int k = 0; k < pieces; ++k)
        add_wall_piece(b, p, a + (e - a) * k / pieces, a + (e - a) * (k + 1.0) / pieces, o, rng);
    }
  }
  const Eigen::Vector2d pad(0.2, 0.2);
  const Eigen::AlignedBox2d area(extent.min() - pad, extent.max() + pad);
  b.add_floor(p.floor, area, 0.0, 1.0);
  b.add_ceiling(p.ceiling, area, o.wall_height_m, 1.0);
  b.set_bounds(Eigen::AlignedBox3d(Eigen::Vector3d(area.min().x(), area.min().y(), 0.0),
                                   Eigen::Vector3d(area.max().x(), area.max().y(), o.wall_height_m)));

  // Lights on a grid, each moved to the most open pixel near its grid point; the start pose
  // at the most open pixel of all.
  cv::Mat clearance;
  cv::distanceTransform(free, clearance, cv::DIST_L2, 5);
  const Eigen::Affine2d T_pixel_world = T_world_pixel.inverse();
  const int step = std::max(1, static_cast<int>(o.light_spacing_m / map.resolution));
  for (int r0 = 0; r0 < free.rows; r0 += step)
    for (int c0 = 0; c0 < free.cols; c0 += step) {
      cv::Point best(-1, -1);
      float best_d = static_cast<float>(0.6 / map.resolution);
      for (int r = r0; r < std::min(free.rows, r0 + step); r += 2)
        for (int c = c0; c < std::min(free.cols, c0 + step); c += 2)
          if (clearance.at<float>(r, c) > best_d) best_d = clearance.at<float>(r, c), best = {c, r};
      if (best.x < 0) continue;
      const Eigen::Vector2d xy = T_world_pixel * Eigen::Vector2d(best.x, best.y);
      b.add_light({{xy.x(), xy.y(), o.wall_height_m - 0.1}, 1.0});
    }
  double max_clear = 0;
  cv::Point most_open;
  cv::minMaxLoc(clearance, nullptr, &max_clear, nullptr, &most_open);
  const Eigen::Vector2d start = T_world_pixel * Eigen::Vector2d(most_open.x, most_open.y);
  b.set_start({start.x(), start.y(), 1.2, 0.0});
  FreeMask mask;
  mask.free = free;
  mask.T_pixel_world = T_pixel_world;
  b.set_free_mask(mask);
  return b.build();
}

}  // namespace kestrel::sim
