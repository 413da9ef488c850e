#include "mapper/render.h"

#include "common/numbers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

namespace kestrel::mapper {

namespace {

const cv::Vec3b kUnknown(60, 60, 60);
const cv::Vec3b kFreeColumn(200, 200, 200);

struct Extent {
  Key min, max;
  int nx = 0, ny = 0;
  int scale = 1;
};

bool extent_of(const VoxelMap& map, const RenderOptions& o, Extent& e) {
  if (!map.key_bounds(e.min, e.max)) return false;
  e.nx = e.max[0] - e.min[0] + 1;
  e.ny = e.max[1] - e.min[1] + 1;
  // At least pixels_per_cell, more for a small map so the image is readable (about 600 px),
  // never a side above max_side_px.
  const int n = std::max(e.nx, e.ny);
  e.scale = std::max(1, std::min(std::max(o.pixels_per_cell, 600 / n), o.max_side_px / n));
  return true;
}

cv::Mat empty_image() { return cv::Mat(64, 64, CV_8UC3, cv::Scalar(kUnknown[0], kUnknown[1], kUnknown[2])); }

void fill_cell(cv::Mat& image, const Extent& e, int kx, int ky, const cv::Vec3b& colour) {
  // World +y is up in the image.
  const int col = (kx - e.min[0]) * e.scale, row = (e.max[1] - ky) * e.scale;
  image(cv::Rect(col, row, e.scale, e.scale)).setTo(cv::Scalar(colour[0], colour[1], colour[2]));
}

void draw_scale_bar(cv::Mat& image, double resolution, int scale, const std::string& text) {
  const int metre_px = static_cast<int>(std::lround(scale / resolution));
  const int y = image.rows - 12;
  cv::line(image, {10, y}, {10 + metre_px, y}, cv::Scalar(255, 255, 255), 3);
  cv::line(image, {10, y}, {10 + metre_px, y}, cv::Scalar(0, 0, 0), 1);
  cv::putText(image, "1 m  " + text, {14 + metre_px, y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

}  // namespace

cv::Vec3b height_colour(double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
  // Piecewise linear through blue, cyan, green, yellow, red.
  const double r = std::clamp(2.0 * t - 1.0, 0.0, 1.0) * 2.0;
  const double g = t < 0.25 ? 4.0 * t : (t < 0.75 ? 1.0 : 4.0 * (1.0 - t));
  const double b = std::clamp(1.0 - 2.0 * t, 0.0, 1.0) * 2.0;
  auto byte = [](double v) { return static_cast<uint8_t>(std::lround(255.0 * std::clamp(v, 0.0, 1.0))); };
  return cv::Vec3b(byte(b), byte(g), byte(r));
}

cv::Mat render_top_view(const VoxelMap& map, const RenderOptions& options) {
  Extent e;
  if (!extent_of(map, options, e)) return empty_image();
  // Per column: the highest occupied key (or -1), and whether anything is known.
  std::vector<int> top(static_cast<size_t>(e.nx) * e.ny, -1);
  std::vector<uint8_t> known(top.size(), 0);
  int z_lo = 0xffff, z_hi = 0;
  map.for_each_cell([&](const Key& k, float v) {
    const size_t i = static_cast<size_t>(k[1] - e.min[1]) * e.nx + (k[0] - e.min[0]);
    known[i] = 1;
    if (map.occupancy(v) == Occupancy::kOccupied) {
      top[i] = std::max(top[i], static_cast<int>(k[2]));
      z_lo = std::min(z_lo, static_cast<int>(k[2]));
      z_hi = std::max(z_hi, static_cast<int>(k[2]));
    }
  });
  cv::Mat image(e.ny * e.scale, e.nx * e.scale, CV_8UC3, cv::Scalar(kUnknown[0], kUnknown[1], kUnknown[2]));
  const double span = std::max(1, z_hi - z_lo);
  for (int y = 0; y < e.ny; ++y) {
    for (int x = 0; x < e.nx; ++x) {
      const size_t i = static_cast<size_t>(y) * e.nx + x;
      if (!known[i]) continue;
      const cv::Vec3b c = top[i] < 0 ? kFreeColumn : height_colour((top[i] - z_lo) / span);
      fill_cell(image, e, e.min[0] + x, e.min[1] + y, c);
    }
  }
  const KeySpace& keys = map.keys();
  const std::string range = z_hi >= z_lo ? "height " + metres(keys.lower(static_cast<uint16_t>(z_lo))) +
                                               " (blue) to " + metres(keys.upper(static_cast<uint16_t>(z_hi))) +
                                               " m (red)"
                                         : "no occupied cell";
  draw_scale_bar(image, map.resolution(), e.scale, range);
  return image;
}

cv::Mat render_slice(const VoxelMap& map, double z_m, const RenderOptions& options) {
  Extent e;
  uint16_t kz = 0;
  if (!extent_of(map, options, e) || !map.keys().key(z_m, kz)) return empty_image();
  cv::Mat image(e.ny * e.scale, e.nx * e.scale, CV_8UC3, cv::Scalar(128, 128, 128));
  map.for_each_cell([&](const Key& k, float v) {
    if (k[2] != kz) return;
    const bool occupied = map.occupancy(v) == Occupancy::kOccupied;
    fill_cell(image, e, k[0], k[1], occupied ? cv::Vec3b(0, 0, 0) : cv::Vec3b(255, 255, 255));
  });
  draw_scale_bar(image, map.resolution(), e.scale, "slice at z = " + metres(z_m) + " m");
  return image;
}

cv::Mat render_perspective(const VoxelMap& map, const RenderOptions& o) {
  Key lo, hi;
  if (!map.key_bounds(lo, hi)) return empty_image();
  const KeySpace& keys = map.keys();
  struct Cube {
    Eigen::Vector3d centre;
    int z;
  };
  std::vector<Cube> cubes;
  int z_lo = 0xffff, z_hi = 0;
  map.for_each_cell([&](const Key& k, float v) {
    if (map.occupancy(v) != Occupancy::kOccupied) return;
    cubes.push_back({{keys.centre(k[0]), keys.centre(k[1]), keys.centre(k[2])}, k[2]});
    z_lo = std::min(z_lo, static_cast<int>(k[2]));
    z_hi = std::max(z_hi, static_cast<int>(k[2]));
  });
  cv::Mat image(o.view_height_px, o.view_width_px, CV_8UC3, cv::Scalar(40, 40, 40));
  if (cubes.empty()) return image;

  // A camera on a sphere around the map's centre, looking at it, far enough to see it all.
  const Eigen::Vector3d a(keys.lower(lo[0]), keys.lower(lo[1]), keys.lower(lo[2]));
  const Eigen::Vector3d b(keys.upper(hi[0]), keys.upper(hi[1]), keys.upper(hi[2]));
  const Eigen::Vector3d centre = 0.5 * (a + b);
  const double radius = 0.5 * (b - a).norm();
  const double az = o.view_azimuth_deg * kPi / 180.0, el = o.view_elevation_deg * kPi / 180.0;
  const Eigen::Vector3d back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const double f = 0.9 * o.view_width_px;  // about 60 degrees across
  // Far enough for the bounding sphere to fit the narrower side of the image.
  const double half_side = 0.5 * std::min(o.view_width_px, o.view_height_px);
  const double distance = 1.05 * radius * std::sqrt(1.0 + (f / half_side) * (f / half_side));
  const Eigen::Vector3d eye = centre + distance * back;
  const Eigen::Vector3d z_axis = -back;
  const Eigen::Vector3d x_axis = z_axis.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  auto project = [&](const Eigen::Vector3d& p, cv::Point2f& px, double& depth) {
    const Eigen::Vector3d d = p - eye;
    depth = d.dot(z_axis);
    if (depth <= 1e-6) return false;
    px = cv::Point2f(static_cast<float>(0.5 * o.view_width_px + f * d.dot(x_axis) / depth),
                     static_cast<float>(0.5 * o.view_height_px + f * d.dot(y_axis) / depth));
    return true;
  };
  // Farthest first, so nearer cubes paint over them. Each cube shows its three faces that
  // face the camera, shaded differently so the surfaces read as 3-D.
  std::sort(cubes.begin(), cubes.end(), [&](const Cube& p, const Cube& q) {
    return (p.centre - eye).squaredNorm() > (q.centre - eye).squaredNorm();
  });
  const double h = 0.5 * map.resolution();
  const double span = std::max(1, z_hi - z_lo);
  for (const Cube& c : cubes) {
    const cv::Vec3b base = height_colour((c.z - z_lo) / span);
    for (int axis = 0; axis < 3; ++axis) {
      const double sign = back[axis] >= 0.0 ? 1.0 : -1.0;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      std::vector<cv::Point> face;
      bool ok = true;
      for (const auto& [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Eigen::Vector3d p = c.centre;
        p[axis] += sign * h;
        p[u] += su * h;
        p[v] += sv * h;
        cv::Point2f px;
        double depth = 0.0;
        ok = ok && project(p, px, depth);
        face.emplace_back(static_cast<int>(std::lround(px.x)), static_cast<int>(std::lround(px.y)));
      }
      if (!ok) continue;
      const double shade = axis == 2 ? 1.0 : (axis == 0 ? 0.75 : 0.55);
      cv::fillConvexPoly(image, face,
                         cv::Scalar(base[0] * shade, base[1] * shade, base[2] * shade), cv::LINE_AA);
    }
  }
  cv::putText(image,
              "occupied cells, height " + metres(keys.lower(static_cast<uint16_t>(z_lo))) + " to " +
                  metres(keys.upper(static_cast<uint16_t>(z_hi))) + " m",
              {10, o.view_height_px - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return image;
}

}  // namespace kestrel::mapper
