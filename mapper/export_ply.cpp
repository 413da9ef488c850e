#include "mapper/export_ply.h"

#include <cstring>
#include <fstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"

namespace kestrel::mapper {

namespace {
struct Point {
  float xyz[3];
  uint8_t rgb[3];
};
}  // namespace

size_t write_ply(const KeyframeStore& keyframes, const std::string& path, double max_range_m) {
  std::vector<Point> points;
  const double max_mm = max_range_m * 1000.0;
  for (const StoredKeyframe* kf : keyframes.in_stored_order()) {
    const RgbdFrame& f = kf->frame;
    const Eigen::Isometry3d T_world_depth = kf->T_world_depth();
    const PinholeCamera& c = f.camera;
    const bool colour = !f.rgb.empty();
    for (int v = 0; v < f.depth_mm.rows; ++v) {
      const uint16_t* depth = f.depth_mm.ptr<uint16_t>(v);
      for (int u = 0; u < f.depth_mm.cols; ++u) {
        if (depth[u] == 0 || depth[u] > max_mm) continue;
        const double z = 0.001 * depth[u];
        const Eigen::Vector3d p =
            T_world_depth * Eigen::Vector3d((u - c.cx) / c.fx * z, (v - c.cy) / c.fy * z, z);
        Point out{};
        for (int a = 0; a < 3; ++a) out.xyz[a] = static_cast<float>(p[a]);
        if (colour) {
          const cv::Vec3b& rgb = f.rgb.at<cv::Vec3b>(v, u);  // R, G, B order (RgbdFrame)
          for (int a = 0; a < 3; ++a) out.rgb[a] = rgb[a];
        } else {
          out.rgb[0] = out.rgb[1] = out.rgb[2] = 160;
        }
        points.push_back(out);
      }
    }
  }
  AtomicFile out(path);  // a failed run leaves no cut cloud that looks whole
  std::ostream& file = out.stream();
  file << "ply\nformat binary_little_endian 1.0\ncomment kestrel mapper: registered keyframes\n"
       << "element vertex " << points.size() << "\n"
       << "property float x\nproperty float y\nproperty float z\n"
       << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  // Written field by field: the struct has padding, and PLY has none. (x86 and ARM are both
  // little-endian, the byte order the header declares.)
  char record[15];
  for (const Point& p : points) {
    std::memcpy(record, p.xyz, 12);
    std::memcpy(record + 12, p.rgb, 3);
    file.write(record, sizeof record);
  }
  out.commit();
  return points.size();
}

}  // namespace kestrel::mapper
