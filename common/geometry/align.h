#pragma once
// Closed-form rigid alignment of two corresponding point sets (absolute orientation).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace kestrel {

/// The rigid T (no scale) minimising sum_i |dst_i - T * src_i|^2 (Horn 1987; Umeyama 1991).
/// Empty when fewer than 3 points are given or they are (nearly) collinear, where the
/// rotation is not determined.
std::optional<Eigen::Isometry3d> align_rigid(const Eigen::Matrix3Xd& src,
                                             const Eigen::Matrix3Xd& dst);

}  // namespace kestrel
