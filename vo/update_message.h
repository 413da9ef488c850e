#pragma once
// VoResult as the VO_UPDATE message (lcmtypes/vo_update_t.lcm): part of the process, not of
// kestrel_vo, which knows nothing of LCM.
//
// Invariant: status and flags take the values of vo_update_t's constants (VoStatus is defined
// with them); the covariance is all zero unless status is STATUS_OK.

#include <Eigen/Geometry>

#include "kestrel/vo_update_t.hpp"
#include "vo/odometry.h"

namespace kestrel::vo {

kestrel::vo_update_t to_message(const VoResult& result, const Eigen::Isometry3d& T_body_camera,
                                double elapsed_ms);

/// The update of a frame that could not be decoded at all.
kestrel::vo_update_t bad_input_message(int64_t utime, int64_t seq);

}  // namespace kestrel::vo
