#include "mapper/scan.h"

#include <algorithm>
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
void pick_grid(int size, int stride, int& offset, int& count) {
  count = size / stride;
  offset = (size - stride * (count - 1) - 1) / 2;
}

cv::Mat pick(const cv::Mat& image, int stride, int u0, int v0, int cols, int rows) {
  if (image.empty()) return {};
  cv::Mat out(rows, cols, image.type());
  // Fixed-size copies for the usual pixel sizes (depth 2 bytes, colour 3): the per-byte loop
  // cost as much as a tenth of a 128x96 insertion.
  auto copy = [&](auto elem_size) {
    constexpr size_t elem = decltype(elem_size)::value;
    for (int r = 0; r < rows; ++r) {
      const uint8_t* in = image.ptr<uint8_t>(v0 + r * stride) + static_cast<size_t>(u0) * elem;
      uint8_t* o = out.ptr<uint8_t>(r);
      const size_t step = static_cast<size_t>(stride) * elem;
      for (int c = 0; c < cols; ++c, in += step, o += elem) std::memcpy(o, in, elem);
    }
  };
  switch (image.elemSize()) {
    case 1: copy(std::integral_constant<size_t, 1>{}); break;
    case 2: copy(std::integral_constant<size_t, 2>{}); break;
    case 3: copy(std::integral_constant<size_t, 3>{}); break;
    case 4: copy(std::integral_constant<size_t, 4>{}); break;
    default: {
      const size_t elem = image.elemSize();
      for (int r = 0; r < rows; ++r) {
        const uint8_t* in = image.ptr<uint8_t>(v0 + r * stride);
        uint8_t* o = out.ptr<uint8_t>(r);
        for (int c = 0; c < cols; ++c) std::memcpy(o + c * elem, in + (u0 + c * stride) * elem, elem);
      }
    }
  }
  return out;
}

// The picked grid of an image of `camera`'s size at `stride` (throws when it is empty), and the
// camera re-scaled to it: picked pixel c sits at u = u0 + stride * c of the original image.
PinholeCamera decimated_camera(const PinholeCamera& camera, int stride, int& u0, int& v0) {
  if (stride < 1) throw std::invalid_argument("decimate: stride must be >= 1");
  int cols = 0, rows = 0;
  pick_grid(camera.width, stride, u0, cols);
  pick_grid(camera.height, stride, v0, rows);
  if (cols < 1 || rows < 1) {
    throw std::invalid_argument("decimate: stride " + std::to_string(stride) +
                                " is larger than the image");
  }
  PinholeCamera out = camera;
  out.width = cols;
  out.height = rows;
  out.fx = camera.fx / stride;
  out.fy = camera.fy / stride;
  out.cx = (camera.cx - u0) / stride;
  out.cy = (camera.cy - v0) / stride;
  return out;
}

void check_scan_input(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera, const char* what) {
  frame.validate(what);
  if (frame.depth_mm.empty()) throw InputError(std::string(what) + ": frame has no depth image");
  if (!se3::is_valid(T_world_camera, 1e-6)) {
    throw InputError(std::string(what) + ": camera pose is not a finite rigid transform");
  }
}

// The rays of the pixels (u0 + stride * c, v0 + stride * r) of frame.depth_mm, c < cam.width,
// r < cam.height, with `cam` the camera of the picked grid.
void fill_scan(const RgbdFrame& frame, const PinholeCamera& cam, int stride, int u0, int v0,
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
  const size_t step = static_cast<size_t>(stride);
  size_t num_points = 0;
  for (int v = 0; v < rows; ++v) {
    const uint16_t* depth = frame.depth_mm.ptr<uint16_t>(v0 + v * stride) + u0;
    const double y_over_z = (v - cy) / fy;
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(cols);
    uint8_t* valid = scan.valid.data() + row;
    octomap::point3d* points = scan.points.data() + row;
    for (int u = 0; u < cols; ++u) {
      const int mm = depth[static_cast<size_t>(u) * step];
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

}  // namespace

RgbdFrame decimate(const RgbdFrame& frame, int stride) {
  if (stride < 1) throw std::invalid_argument("decimate: stride must be >= 1");
  if (stride == 1) return frame;
  int u0 = 0, v0 = 0;
  const PinholeCamera cam = decimated_camera(frame.camera, stride, u0, v0);
  RgbdFrame out = frame;
  out.rgb = pick(frame.rgb, stride, u0, v0, cam.width, cam.height);
  out.depth_mm = pick(frame.depth_mm, stride, u0, v0, cam.width, cam.height);
  out.camera = cam;
  return out;
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
  fill_scan(frame, frame.camera, 1, 0, 0, T_world_camera, options, scan);
}

void make_decimated_scan(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                         const ScanOptions& options, const char* what, Scan& scan) {
  check_scan_input(frame, T_world_camera, what);
  int u0 = 0, v0 = 0;
  const PinholeCamera cam = decimated_camera(frame.camera, options.stride, u0, v0);
  fill_scan(frame, cam, options.stride, u0, v0, T_world_camera, options, scan);
}

}  // namespace kestrel::mapper
