#include "mapper/scan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "common/error.h"
#include "common/geometry/se3.h"

namespace kestrel::mapper {

octomap::Pointcloud Scan::valid_points() const {
  octomap::Pointcloud cloud;
  cloud.reserve(num_points);
  for (size_t i = 0; i < points.size(); ++i) {
    if (valid[i]) cloud.push_back(points[i]);
  }
  return cloud;
}

namespace {

// First picked pixel and count along an axis of `size` pixels, so that the picked grid is
// centred: 640 px at stride 5 -> pixels 2, 7, ..., 637 (128 of them).
void pick_axis(int size, int stride, int& offset, int& count) {
  count = size / stride;
  offset = (size - stride * (count - 1) - 1) / 2;
}

// The grid a frame is read on: an ideal pinhole camera at `stride` (a grid centred in the
// image: picked pixel c sits at u = u0 + stride * c of the original), and, when the source
// reports lens distortion, the raw pixel each node reads.
struct PickGrid {
  PinholeCamera source;  ///< the frame's camera this grid was made for
  int stride = 0;
  PinholeCamera camera;  ///< the grid's, without distortion
  int u0 = 0, v0 = 0;
  // Without distortion empty: node (c, r) reads raw pixel (u0 + stride c, v0 + stride r).
  // Otherwise per node (row-major) the raw pixel nearest to where the lens puts the node's
  // ideal pixel, {-1, -1} when that lies outside the image (the node has no reading).
  std::vector<std::array<int16_t, 2>> raw;

  bool made_for(const PinholeCamera& c, int s) const {
    return s == stride && c.width == source.width && c.height == source.height && c.fx == source.fx &&
           c.fy == source.fy && c.cx == source.cx && c.cy == source.cy && c.distortion == source.distortion;
  }
};

// The grid of `camera` at `stride` (throws when it is empty). The last one is kept per thread:
// a mapper reads every frame of a camera on the same grid, and a distorted grid costs one
// lens evaluation per node to make (a few milliseconds at 640 x 480). The reference is valid
// until the next call.
const PickGrid& pick_grid(const PinholeCamera& camera, int stride) {
  // Two slots, so that the undistorted grids (the decimated frames a rebuild re-reads, cheap to
  // make) never evict the distorted one of the live camera.
  thread_local PickGrid distorted, plain;
  PickGrid& grid = camera.distorted() ? distorted : plain;
  if (grid.made_for(camera, stride)) return grid;
  if (stride < 1) throw std::invalid_argument("decimate: stride must be >= 1");
  int cols = 0, rows = 0;
  pick_axis(camera.width, stride, grid.u0, cols);
  pick_axis(camera.height, stride, grid.v0, rows);
  if (cols < 1 || rows < 1) {
    throw std::invalid_argument("decimate: stride " + std::to_string(stride) +
                                " is larger than the image");
  }
  grid.stride = 0;  // not valid until complete (an exception below leaves it unmatched)
  grid.camera = camera;
  grid.camera.width = cols;
  grid.camera.height = rows;
  grid.camera.fx = camera.fx / stride;
  grid.camera.fy = camera.fy / stride;
  grid.camera.cx = (camera.cx - grid.u0) / stride;
  grid.camera.cy = (camera.cy - grid.v0) / stride;
  grid.camera.distortion = {};
  grid.raw.clear();
  if (camera.distorted()) {
    grid.raw.resize(static_cast<size_t>(cols) * static_cast<size_t>(rows));
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const Eigen::Vector2d p = camera.distort(grid.u0 + stride * c, grid.v0 + stride * r);
        const long x = std::lround(p.x()), y = std::lround(p.y());
        const bool inside = x >= 0 && y >= 0 && x < camera.width && y < camera.height;
        grid.raw[static_cast<size_t>(r) * static_cast<size_t>(cols) + static_cast<size_t>(c)] =
            inside ? std::array<int16_t, 2>{int16_t(x), int16_t(y)} : std::array<int16_t, 2>{-1, -1};
      }
    }
  }
  grid.source = camera;
  grid.stride = stride;
  return grid;
}

// Copies the pixels of `image` that the nodes of `grid` read into `out`; `size` is the pixel
// size in bytes, a compile-time constant for the usual ones (depth 2 bytes, colour 3): a
// per-byte copy cost as much as a tenth of a 128x96 insertion.
template <class Size>
void copy_picked(const cv::Mat& image, const PickGrid& grid, Size size, cv::Mat& out) {
  const size_t elem = size;
  const int cols = grid.camera.width, rows = grid.camera.height;
  for (int r = 0; r < rows; ++r) {
    uint8_t* o = out.ptr<uint8_t>(r);
    if (grid.raw.empty()) {
      const uint8_t* in = image.ptr<uint8_t>(grid.v0 + r * grid.stride) + static_cast<size_t>(grid.u0) * elem;
      const size_t step = static_cast<size_t>(grid.stride) * elem;
      for (int c = 0; c < cols; ++c, in += step, o += elem) std::memcpy(o, in, elem);
    } else {
      // Through the lens: each node's pixel wherever the lens put it; none outside the image.
      const std::array<int16_t, 2>* raw = grid.raw.data() + static_cast<size_t>(r) * static_cast<size_t>(cols);
      for (int c = 0; c < cols; ++c, o += elem) {
        if (raw[c][0] < 0) {
          std::memset(o, 0, elem);
        } else {
          std::memcpy(o, image.ptr<uint8_t>(raw[c][1]) + static_cast<size_t>(raw[c][0]) * elem, elem);
        }
      }
    }
  }
}

cv::Mat pick(const cv::Mat& image, const PickGrid& grid) {
  if (image.empty()) return {};
  cv::Mat out(grid.camera.height, grid.camera.width, image.type());
  switch (image.elemSize()) {
    case 1: copy_picked(image, grid, std::integral_constant<size_t, 1>{}, out); break;
    case 2: copy_picked(image, grid, std::integral_constant<size_t, 2>{}, out); break;
    case 3: copy_picked(image, grid, std::integral_constant<size_t, 3>{}, out); break;
    case 4: copy_picked(image, grid, std::integral_constant<size_t, 4>{}, out); break;
    default: copy_picked(image, grid, image.elemSize(), out);
  }
  return out;
}

void check_scan_input(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera, const char* what) {
  frame.validate(what);
  if (frame.depth_mm.empty()) throw InputError(std::string(what) + ": frame has no depth image");
  if (!se3::is_valid(T_world_camera, 1e-6)) {
    throw InputError(std::string(what) + ": camera pose is not a finite rigid transform");
  }
}

// The rays of the nodes of `grid` in frame.depth_mm. `row_reader(v)` gives, for row v of the
// grid, a callable u -> the reading of node (u, v) in mm.
template <class RowReader>
void fill_scan(const RgbdFrame& frame, const PinholeCamera& cam, RowReader row_reader,
               const Eigen::Isometry3d& T_world_camera, const ScanOptions& options, Scan& scan) {
  scan.num_points = 0;
  scan.utime = frame.depth_utime != 0 ? frame.depth_utime : frame.utime;
  scan.T_world_camera = T_world_camera;
  scan.camera = cam;
  scan.cols = cam.width;
  scan.rows = cam.height;
  const Eigen::Vector3d t = T_world_camera.translation();
  scan.origin = octomap::point3d(static_cast<float>(t.x()), static_cast<float>(t.y()),
                                 static_cast<float>(t.z()));
  const size_t n = static_cast<size_t>(scan.cols) * static_cast<size_t>(scan.rows);
  scan.points.resize(n);
  scan.valid.resize(n);

  const Eigen::Matrix3d R = T_world_camera.linear();
  // A reading is a ray iff mm != 0 and !(mm < min_range in mm): for an integer mm that is
  // mm >= the smallest integer not below the minimum (and >= 1).
  const double min_depth_mm = options.min_range_m * 1000.0;
  int min_mm = 1;
  if (min_depth_mm > 1.0) min_mm = static_cast<int>(std::ceil(std::min(min_depth_mm, 65536.0)));
  // Everything the loop reads, in locals: its byte stores (valid) may alias anything, so
  // members would be reloaded for every pixel.
  const int cols = scan.cols, rows = scan.rows;
  const double cx = cam.cx, fx = cam.fx, cy = cam.cy, fy = cam.fy;
  size_t num_points = 0;
  for (int v = 0; v < rows; ++v) {
    const auto reading = row_reader(v);
    const double y_over_z = (v - cy) / fy;
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(cols);
    uint8_t* valid = scan.valid.data() + row;
    octomap::point3d* points = scan.points.data() + row;
    for (int u = 0; u < cols; ++u) {
      const int mm = reading(u);
      const bool ok = mm >= min_mm;
      valid[u] = ok ? 1 : 0;
      if (!ok) continue;
      const double z = 0.001 * mm;
      const Eigen::Vector3d p_in_camera((u - cx) / fx * z, y_over_z * z, z);
      const Eigen::Vector3d p = R * p_in_camera + t;
      points[u] = octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                   static_cast<float>(p.z()));
      ++num_points;
    }
  }
  scan.num_points = num_points;
}

void fill_scan(const RgbdFrame& frame, const PickGrid& grid, const Eigen::Isometry3d& T_world_camera,
               const ScanOptions& options, Scan& scan) {
  const cv::Mat& depth = frame.depth_mm;
  if (grid.raw.empty()) {
    const size_t step = static_cast<size_t>(grid.stride);
    auto rows = [&](int v) {
      const uint16_t* in = depth.ptr<uint16_t>(grid.v0 + v * grid.stride) + grid.u0;
      return [in, step](int u) -> int { return in[static_cast<size_t>(u) * step]; };
    };
    fill_scan(frame, grid.camera, rows, T_world_camera, options, scan);
  } else {
    const size_t cols = static_cast<size_t>(grid.camera.width);
    auto rows = [&](int v) {
      const std::array<int16_t, 2>* raw = grid.raw.data() + static_cast<size_t>(v) * cols;
      return [raw, &depth](int u) -> int {
        const std::array<int16_t, 2> p = raw[u];
        return p[0] < 0 ? 0 : depth.ptr<uint16_t>(p[1])[p[0]];
      };
    };
    fill_scan(frame, grid.camera, rows, T_world_camera, options, scan);
  }
}

}  // namespace

RgbdFrame decimate(const RgbdFrame& frame, int stride) {
  if (stride < 1) throw std::invalid_argument("decimate: stride must be >= 1");
  if (stride == 1 && !frame.camera.distorted()) return frame;
  const PickGrid& grid = pick_grid(frame.camera, stride);
  RgbdFrame out = frame;
  out.rgb = pick(frame.rgb, grid);  // = decimate_colour()
  out.depth_mm = pick(frame.depth_mm, grid);
  out.camera = grid.camera;
  return out;
}

cv::Mat decimate_colour(const cv::Mat& rgb, const PinholeCamera& camera, int stride) {
  if (stride < 1) throw std::invalid_argument("decimate_colour: stride must be >= 1");
  if (stride == 1 && !camera.distorted()) return rgb;
  return pick(rgb, pick_grid(camera, stride));
}

Scan make_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
               const ScanOptions& options, const char* what) {
  Scan scan;
  make_scan(frame, T_world_camera, options, what, scan);
  return scan;
}

void make_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
               const ScanOptions& options, const char* what, Scan& scan) {
  check_scan_input(frame, T_world_camera, what);
  fill_scan(frame, pick_grid(frame.camera, 1), T_world_camera, options, scan);
}

void make_decimated_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                         const ScanOptions& options, const char* what, Scan& scan) {
  check_scan_input(frame, T_world_camera, what);
  fill_scan(frame, pick_grid(frame.camera, options.stride), T_world_camera, options, scan);
}

}  // namespace kestrel::mapper
