#include "test/vo/synthetic_tum.h"

#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/camera.h"
#include "common/image/image_io.h"
#include "common/time.h"
#include "test/tum/tum_fixture.h"
#include "test/vo/synthetic_scene.h"

namespace kestrel::vo::test {

namespace fs = std::filesystem;

Eigen::Isometry3d line_pose(double k) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.01 * k, -0.004 * k, 0.002 * k);
  return T;
}

Trajectory line_ground_truth(int64_t t0, int64_t period_us, int frames) {
  Trajectory gt;
  for (int64_t t = t0 - 50000; t <= t0 + period_us * (frames - 1) + 50000; t += 10000)
    gt.push_back(t, line_pose(double(t - t0) / double(period_us)));
  return gt;
}

fs::path write_tum_folder(const fs::path& parent, const TumFolderSpec& spec) {
  const fs::path folder = parent / "rgbd_dataset_synthetic";
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  static const SyntheticScene scene(23);
  const PinholeCamera camera = PinholeCamera::vga(525.0, 525.0, 319.5, 239.5);
  std::ostringstream rgb, depth;
  rgb << "# color images\n";
  depth << "# depth maps\n";
  for (int k = 0; k < spec.frames + (spec.extra_rgb ? 1 : 0); ++k) {
    const bool extra = k == spec.frames;
    const int64_t t = extra ? kTumT0 + kTumPeriod * (k - 1) + 1000000 : kTumT0 + kTumPeriod * k;
    const RgbdFrame f = scene.render(line_pose(k), camera, t);
    cv::Mat bgr, raw;
    cv::cvtColor(f.rgb, bgr, cv::COLOR_RGB2BGR);
    f.depth_mm.convertTo(raw, CV_16UC1, 5.0);  // TUM's 1/5000 m
    if (k >= spec.blank_depth_from) raw.setTo(cv::Scalar::all(0));
    const std::string name = std::to_string(k) + ".png";
    image::write_png((folder / "rgb" / name).string(), bgr);
    rgb << format_seconds(t) << " rgb/" << name << "\n";
    if (!extra) {
      image::write_png((folder / "depth" / name).string(), raw);
      depth << format_seconds(t + spec.depth_shift_us) << " depth/" << name << "\n";
    }
  }
  ::kestrel::test::write_text(folder / "rgb.txt", rgb.str());
  ::kestrel::test::write_text(folder / "depth.txt", depth.str());
  write_tum_trajectory((folder / "groundtruth.txt").string(), line_ground_truth(kTumT0, kTumPeriod, spec.frames));
  return folder;
}

}  // namespace kestrel::vo::test
