#pragma once
// Moves a depth image from one camera to another (registration of Kinect depth to its RGB
// camera, and the inverse for writing fakenect dumps).
//
// Each valid source pixel is back-projected with its depth, transformed into the target
// camera, projected and written to the nearest target pixel (a forward warp). Where several
// source pixels land on one target pixel the nearest surface wins (z-buffer), so a
// foreground edge is never hidden by the background behind it. Target pixels that no source
// pixel reaches stay 0 ("no reading"): the warp does not fill holes, which would invent depth.
//
// Invariants: the output depth is the z of the transformed point in the target camera (not
// the source depth); with the same camera on both sides and an identity transform the output
// equals the input exactly.

#include <Eigen/Geometry>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/camera.h"

namespace kestrel::kinect {

class DepthWarp {
 public:
  /// T_to_from maps points of the source camera into the target camera.
  DepthWarp(const PinholeCamera& from, const PinholeCamera& to, const Eigen::Isometry3d& T_to_from);

  /// depth_from: CV_32FC1 metres of from.width x from.height; zero, negative and NaN are "no
  /// reading". Returns CV_32FC1 metres of to.width x to.height, 0 = no reading.
  cv::Mat operator()(const cv::Mat& depth_from) const;

 private:
  PinholeCamera from_;
  PinholeCamera to_;
  // Per source pixel, R_to_from times its ray (x/z, y/z, 1): the transformed point is then
  // z * ray_in_to_ + t_to_from_, three multiply-adds per pixel.
  std::vector<Eigen::Vector3f> ray_in_to_;
  Eigen::Vector3f t_to_from_;
};

}  // namespace kestrel::kinect
