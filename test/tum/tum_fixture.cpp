#include "common/image/image_io.h"
#include "test/tum/tum_fixture.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/time.h"

namespace kestrel::test {
namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

cv::Vec3b TumFixture::rgb_at(int k, int row, int col) {
  return {static_cast<uint8_t>((col + 3 * k) % 256), static_cast<uint8_t>((row * 2 + k) % 256),
          static_cast<uint8_t>((row + col + 50 * k) % 256)};
}

uint16_t TumFixture::depth_raw_at(int k, int row, int col) {
  if ((row * 640 + col) % 7 == 3) return 0;
  // 1.0 m + 0.1 m per frame, rising 1 m across the image: 5000 .. 10495 units.
  return static_cast<uint16_t>(5000 + 500 * k + (col * 5000) / 640 + row % 3);
}

cv::Mat TumFixture::rgb_image(int k) {
  cv::Mat m(480, 640, CV_8UC3);
  for (int r = 0; r < 480; ++r)
    for (int c = 0; c < 640; ++c) m.at<cv::Vec3b>(r, c) = rgb_at(k, r, c);
  return m;
}

cv::Mat TumFixture::depth_raw_image(int k) {
  cv::Mat m(480, 640, CV_16UC1);
  for (int r = 0; r < 480; ++r)
    for (int c = 0; c < 640; ++c) m.at<uint16_t>(r, c) = depth_raw_at(k, r, c);
  return m;
}

cv::Vec3d TumFixture::accel_at(int i) {
  // Whole counts of 9.80665 / 819 m/s^2, like the Kinect's (and TUM's) readings.
  const double count = 9.80665 / 819.0;
  return {count * (57 + i % 5), count * (653 - i % 3), count * (-468 + i % 7)};
}

int TumFixture::accel_samples() const {
  return static_cast<int>((rgb_utime(options_.frames - 1) + 100000 - accel_utime(0)) / 5000) + 1;
}

TumFixture::TumFixture(const fs::path& parent, TumFixtureOptions options)
    : folder_(parent / options.name), options_(options) {
  fs::create_directories(folder_ / "rgb");
  fs::create_directories(folder_ / "depth");
  std::ostringstream rgb_list, depth_list;
  rgb_list << "# color images\n# file: 'fixture.bag'\n# timestamp filename\n";
  depth_list << "# depth maps\n# file: 'fixture.bag'\n# timestamp filename\n";
  for (int k = 0; k < options.frames; ++k) {
    const std::string rgb_name = "rgb/" + format_seconds(rgb_utime(k)) + ".png";
    const std::string depth_name = "depth/" + format_seconds(depth_utime(k)) + ".png";
    cv::Mat bgr;
    cv::cvtColor(rgb_image(k), bgr, cv::COLOR_RGB2BGR);
    image::write_png((folder_ / rgb_name).string(), bgr);
    image::write_png((folder_ / depth_name).string(), depth_raw_image(k));
    rgb_list << format_seconds(rgb_utime(k)) << ' ' << rgb_name << '\n';
    depth_list << format_seconds(depth_utime(k)) << ' ' << depth_name << '\n';
  }
  write_text(folder_ / "rgb.txt", rgb_list.str());
  write_text(folder_ / "depth.txt", depth_list.str());

  if (options.ground_truth) {
    std::ostringstream gt;
    gt << "# ground truth trajectory\n# file: 'fixture.bag'\n# timestamp tx ty tz qx qy qz qw\n";
    for (int64_t t = kT0 - 100000; t <= rgb_utime(options.frames - 1) + 100000; t += 10000) {
      const double s = 1e-6 * static_cast<double>(t - kT0);
      // Moving along x, turning about z: q = (0, 0, sin(a/2), cos(a/2)).
      const double a = 0.5 * s;
      gt << format_seconds(t) << ' ' << 1.0 + 0.2 * s << " 2 1.5 0 0 " << std::sin(a / 2) << ' '
         << std::cos(a / 2) << '\n';
    }
    write_text(folder_ / "groundtruth.txt", gt.str());
  }
  if (options.accelerometer) {
    std::ostringstream acc;
    acc << "# accelerometer data\n# file: 'fixture.bag'\n# timestamp ax ay az\n";
    acc.precision(9);
    for (int i = 0; i < accel_samples(); ++i) {
      const cv::Vec3d a = accel_at(i);
      acc << format_seconds(accel_utime(i)) << ' ' << a[0] << ' ' << a[1] << ' ' << a[2] << '\n';
    }
    write_text(folder_ / "accelerometer.txt", acc.str());
  }
}

namespace {
TumFixtureOptions with(int frames, const std::string& name) {
  TumFixtureOptions o;
  o.frames = frames;
  o.name = name;
  return o;
}
}  // namespace

TumFixture::TumFixture(const fs::path& parent, int frames, const std::string& name)
    : TumFixture(parent, with(frames, name)) {}

void TumFixture::edit_line(const std::string& file, int line, const std::string& text) const {
  std::ifstream in(folder_ / file);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  if (line == 0) {
    lines.push_back(text);
  } else {
    lines.at(static_cast<size_t>(line - 1)) = text;
  }
  std::ostringstream out;
  for (const auto& l : lines) out << l << '\n';
  write_text(folder_ / file, out.str());
}

}  // namespace kestrel::test
