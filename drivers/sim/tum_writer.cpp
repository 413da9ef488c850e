#include "drivers/sim/tum_writer.h"

#include <filesystem>
#include <iomanip>
#include <sstream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "common/time.h"

namespace kestrel::sim {
namespace fs = std::filesystem;

namespace {

// Compression level 1 and one fixed filter: these folders are scratch data, written at
// simulation speed. Against level 1 with adaptive filters, a rendered VGA frame's colour image
// with kAverage encodes in half the time and 0.3 % larger, its depth image with kNone in a third
// of the time and 20 % smaller (docs/decisions/2026-12-02-sim-export-png-filters.md). Written in
// place, not atomically: an fsync per frame would be most of the run.
void write_image(const std::string& path, const cv::Mat& image, image::PngFilter filter) {
  const std::vector<uint8_t> png = image::encode_png(image, 1, filter);
  // in-place: a recording, one image per frame; an fsync per frame would be most of the run
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!out.flush()) throw InputError(path + ": cannot write image");
}

void pose_line(std::ostream& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d& p = T.translation();
  out << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w();
}

}  // namespace

// in-place: a recording, its lists appended a line per sample
std::ofstream TumFolderWriter::open(const std::string& name, const char* header) {
  const std::string path = (fs::path(folder_) / name).string();
  // in-place: a recording, its lists appended a line per sample
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot create file");
  out << header;
  out << std::setprecision(9);
  return out;
}

TumFolderWriter::TumFolderWriter(const std::string& folder, const PinholeCamera& camera,
                                 const Eigen::Isometry3d& T_body_camera)
    : folder_(folder), T_body_camera_(T_body_camera) {
  std::error_code ec;
  for (const char* sub : {"rgb", "depth"}) {
    fs::create_directories(fs::path(folder) / sub, ec);
    if (ec) throw InputError((fs::path(folder) / sub).string() + ": cannot create folder: " + ec.message());
  }
  rgb_ = open("rgb.txt", "# color images\n# file: 'kestrel-sim'\n# timestamp filename\n");
  depth_ = open("depth.txt", "# depth maps\n# file: 'kestrel-sim'\n# timestamp filename\n");
  ground_truth_ = open("groundtruth.txt",
                       "# ground truth trajectory (RGB optical frame in the world)\n# file: 'kestrel-sim'\n"
                       "# timestamp tx ty tz qx qy qz qw\n");
  accelerometer_ = open("accelerometer.txt",
                        "# accelerometer data (Kinect accelerometer axes)\n# file: 'kestrel-sim'\n# timestamp ax ay az\n");
  imu_ = open("imu.txt", "# imu (body frame: x forward, y left, z up)\n# timestamp gx gy gz ax ay az\n");
  biases_ = open("imu_biases.txt", "# true imu biases (as added to the readings)\n# timestamp bgx bgy bgz bax bay baz\n");
  std::ostringstream cam;  // a whole file, written at once
  cam << std::setprecision(9) << "# fx fy cx cy width height\n"
      << camera.fx << ' ' << camera.fy << ' ' << camera.cx << ' ' << camera.cy << ' ' << camera.width << ' '
      << camera.height << "\n# T_body_camera x y z qx qy qz qw\nT_body_camera";
  pose_line(cam, T_body_camera);
  cam << "\n# the sensor profile (sensors/profiles/)\nsensor " << sensor_model::kSimulator << '\n';
  write_file_atomically((fs::path(folder) / "camera.txt").string(), cam.str());
}

void TumFolderWriter::add_pose(int64_t utime, const Eigen::Isometry3d& T_world_camera) {
  if (utime <= last_pose_utime_) return;  // an IMU sample and a frame can share a time stamp
  last_pose_utime_ = utime;
  ground_truth_ << format_seconds(utime);
  pose_line(ground_truth_, T_world_camera);
  ground_truth_ << '\n';
}

void TumFolderWriter::add_frame(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera) {
  const std::string stamp = format_seconds(frame.utime);
  const std::string depth_stamp = format_seconds(frame.depth_utime);
  cv::Mat bgr;
  cv::cvtColor(frame.rgb, bgr, cv::COLOR_RGB2BGR);
  write_image((fs::path(folder_) / "rgb" / (stamp + ".png")).string(), bgr, image::PngFilter::kAverage);
  // TUM depth: 5000 units per metre, i.e. 5 per millimetre (saturating above 13.1 m).
  cv::Mat depth;
  frame.depth_mm.convertTo(depth, CV_16UC1, 5.0);
  write_image((fs::path(folder_) / "depth" / (depth_stamp + ".png")).string(), depth, image::PngFilter::kNone);
  rgb_ << stamp << " rgb/" << stamp << ".png\n";
  depth_ << depth_stamp << " depth/" << depth_stamp << ".png\n";
  add_pose(frame.utime, T_world_camera);
  ++frames_;
}

void TumFolderWriter::add_imu(int64_t utime, const ImuSample& s, const Eigen::Isometry3d& T_world_camera) {
  const std::string stamp = format_seconds(utime);
  imu_ << stamp << ' ' << s.gyro.x() << ' ' << s.gyro.y() << ' ' << s.gyro.z() << ' ' << s.accel.x() << ' '
       << s.accel.y() << ' ' << s.accel.z() << '\n';
  biases_ << stamp << ' ' << s.gyro_bias.x() << ' ' << s.gyro_bias.y() << ' ' << s.gyro_bias.z() << ' '
          << s.accel_bias.x() << ' ' << s.accel_bias.y() << ' ' << s.accel_bias.z() << '\n';
  // Kinect accelerometer axes: the optical frame turned 180 degrees about its z.
  const Eigen::Vector3d a_camera = T_body_camera_.linear().transpose() * s.accel;
  accelerometer_ << stamp << ' ' << -a_camera.x() << ' ' << -a_camera.y() << ' ' << a_camera.z() << '\n';
  add_pose(utime, T_world_camera);
}

void TumFolderWriter::close() {
  for (auto* f : {&rgb_, &depth_, &ground_truth_, &accelerometer_, &imu_, &biases_}) {
    f->flush();
    if (!*f) throw InputError(folder_ + ": write error (disk full?)");
    f->close();
  }
}

}  // namespace kestrel::sim
