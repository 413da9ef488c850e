#include "drivers/sim/realism.h"

#include <Eigen/Dense>
#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace kestrel::sim {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

}  // namespace

FrameStats frame_stats(const RgbdFrame& frame) {
  FrameStats s;
  cv::Mat grey;
  cv::cvtColor(frame.rgb, grey, cv::COLOR_RGB2GRAY);
  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey, corners, 20, true);
  s.fast_corners = static_cast<int>(corners.size());
  s.mean_grey = cv::mean(grey)[0];
  s.saturated = static_cast<double>(cv::countNonZero(grey >= 250)) / static_cast<double>(grey.total());
  s.valid_depth = static_cast<double>(cv::countNonZero(frame.depth_mm)) / static_cast<double>(frame.depth_mm.total());
  constexpr int kBlock = 8;
  Eigen::Matrix<double, kBlock * kBlock, 3> A;
  Eigen::Matrix<double, kBlock * kBlock, 1> z;
  for (int v0 = 0; v0 + kBlock <= frame.depth_mm.rows; v0 += kBlock)
    for (int u0 = 0; u0 + kBlock <= frame.depth_mm.cols; u0 += kBlock) {
      bool usable = true;
      for (int dv = 0; dv < kBlock && usable; ++dv)
        for (int du = 0; du < kBlock; ++du) {
          const double m = frame.depth_mm.at<uint16_t>(v0 + dv, u0 + du) * 1e-3;
          if (m < 1.0 || m > 3.0) {
            usable = false;
            break;
          }
          const int i = dv * kBlock + du;
          A.row(i) << du, dv, 1.0;
          z(i) = m;
        }
      if (!usable) continue;
      const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(z);
      const double rms = std::sqrt((A * plane - z).squaredNorm() / (kBlock * kBlock - 3));
      if (rms > 0.05) continue;
      const double mean_z = z.mean();
      s.noise_k.push_back(rms / (mean_z * mean_z));
    }
  return s;
}

SequenceStats summarise(const std::vector<FrameStats>& frames) {
  SequenceStats out;
  out.frames = static_cast<int>(frames.size());
  std::vector<double> fast, valid, noise, grey, saturated;
  for (const FrameStats& f : frames) {
    fast.push_back(f.fast_corners);
    valid.push_back(f.valid_depth);
    grey.push_back(f.mean_grey);
    saturated.push_back(f.saturated);
    out.frames_over_a_tenth_saturated += f.saturated > 0.1 ? 1.0 / static_cast<double>(frames.size()) : 0.0;
    noise.insert(noise.end(), f.noise_k.begin(), f.noise_k.end());
  }
  out.fast_corners_median = median(fast);
  out.valid_depth_median = median(valid);
  out.noise_k_median = median(noise);
  out.noise_blocks = static_cast<int>(noise.size());
  out.mean_grey_median = median(grey);
  out.saturated_median = median(saturated);
  if (!grey.empty()) {
    std::sort(grey.begin(), grey.end());
    out.mean_grey_p95 = grey[std::min(grey.size() - 1, static_cast<size_t>(0.95 * static_cast<double>(grey.size())))];
    out.mean_grey_max = grey.back();
    out.saturated_max = *std::max_element(saturated.begin(), saturated.end());
  }
  return out;
}

}  // namespace kestrel::sim
