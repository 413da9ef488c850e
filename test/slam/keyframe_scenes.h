#pragma once
// Scenes for the keyframe-feature tests (timing and lens): a textured image ORB finds corners
// all over, the known motion of a moving camera, and where a rolling shutter puts a point.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/camera.h"
#include "sensors/frame_motion.h"

namespace kestrel::slam::test {

/// A grey texture of sharp 8 x 8 pixel cells (noise from `seed`): corners all over the image.
inline cv::Mat texture(const PinholeCamera& camera, int seed) {
  cv::Mat noise(camera.height, camera.width, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat grey;
  cv::resize(noise(cv::Rect(0, 0, camera.width / 8, camera.height / 8)), grey, noise.size(), 0, 0,
             cv::INTER_NEAREST);
  return grey;
}

/// A camera moving with twist (rho, phi) per second, its depth image `depth_offset_s` after the
/// colour image and its rows read out over `readout_s`.
inline sensors::FrameMotion moving(const Eigen::Vector3d& rho, const Eigen::Vector3d& phi, double depth_offset_s,
                              double readout_s) {
  sensors::FrameMotion m;
  m.known = true;
  m.twist_per_s << rho, phi;
  m.depth_offset_s = depth_offset_s;
  m.readout_s = readout_s;
  return m;
}

/// Where a rolling shutter that reads `rows` rows over `readout_s` puts point p seen on `row`,
/// for a camera turning at w rad/s about its y axis: row `row` was read
/// s = (row - (rows - 1) / 2) * readout_s / rows after the middle row, so p is carried to the
/// middle row's camera as p + s (w x p) = (x + s w z, y, z - s w x).
inline Eigen::Vector3d carried_to_middle_row(const Eigen::Vector3d& p, double row, int rows, double readout_s,
                                             double w) {
  const double s = (row - 0.5 * (rows - 1)) * readout_s / rows;
  return {p.x() + s * w * p.z(), p.y(), p.z() - s * w * p.x()};
}

}  // namespace kestrel::slam::test
