#pragma once
// A tiny TUM RGB-D sequence folder written by the tests themselves (no data files in the
// repository): a few 640x480 frames whose every pixel is a known function of the frame and
// the pixel, lists with TUM's '#' header lines, ground truth and an accelerometer log.
//
// Frame k (0-based): RGB time t0 + k * 33333 us, depth time 1000 us later; colour
// rgb_at(k, row, col); depth a plane tilted along the columns, depth_raw_at(k, row, col) in
// TUM units (1/5000 m), with a hole (0) every 7th pixel. Ground truth at 100 Hz and the
// accelerometer at 200 Hz cover the frames with 0.1 s to spare on both sides.

#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core/mat.hpp>

namespace kestrel::test {

struct TumFixtureOptions {
  std::string name = "rgbd_dataset_freiburg1_fixture";  ///< folder name (camera detection)
  int frames = 5;
  bool ground_truth = true;
  bool accelerometer = true;
};

class TumFixture {
 public:
  static constexpr int64_t kT0 = 1305031229528748;  ///< first RGB time, us
  static constexpr int64_t kPeriod = 33333;         ///< frame period, us
  static constexpr int64_t kDepthDelay = 1000;      ///< depth time - RGB time, us

  TumFixture(const std::filesystem::path& parent, TumFixtureOptions options = {});
  /// `frames` frames, with ground truth and accelerometer, in parent/name.
  TumFixture(const std::filesystem::path& parent, int frames,
             const std::string& name = TumFixtureOptions().name);

  const std::filesystem::path& folder() const { return folder_; }
  std::filesystem::path operator/(const std::string& name) const { return folder_ / name; }
  int frames() const { return options_.frames; }

  static int64_t rgb_utime(int k) { return kT0 + k * kPeriod; }
  static int64_t depth_utime(int k) { return rgb_utime(k) + kDepthDelay; }
  /// R, G, B of frame k at (row, col).
  static cv::Vec3b rgb_at(int k, int row, int col);
  /// TUM raw depth (1/5000 m) of frame k at (row, col); 0 = hole.
  static uint16_t depth_raw_at(int k, int row, int col);
  /// The whole images, as the files hold them (colour in R, G, B order).
  static cv::Mat rgb_image(int k);
  static cv::Mat depth_raw_image(int k);
  /// Accelerometer sample i (Kinect axes) and its time: 200 Hz from t0 - 0.1 s.
  static int64_t accel_utime(int i) { return kT0 - 100000 + i * 5000; }
  static cv::Vec3d accel_at(int i);
  int accel_samples() const;

  /// Replaces line `line` (1-based) of `file` with `text`, or appends it when line is 0.
  void edit_line(const std::string& file, int line, const std::string& text) const;

 private:
  std::filesystem::path folder_;
  TumFixtureOptions options_;
};

/// Writes `text` to `path`, replacing it.
void write_text(const std::filesystem::path& path, const std::string& text);

}  // namespace kestrel::test
