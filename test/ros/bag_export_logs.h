#pragma once
// Small kestrel logs of hand-made messages, for bag-export's tests: known answers.

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

#include "kestrel/state_t.hpp"

namespace kestrel::test {

/// The camera 10 cm ahead of the body, looking along the body's x (optical z forward, x right,
/// y down).
Eigen::Isometry3d body_camera();

/// An EKF STATE, STATUS_OK, with a zero 15x15 covariance.
kestrel::state_t make_state(int64_t utime, const Eigen::Isometry3d& T_world_body, const Eigen::Vector3d& v_world,
                            const Eigen::Vector3d& omega_body);

/// A log of `n` STATEs 10 ms apart from t = 1 s on a helix, each with a distinct covariance,
/// and (with `with_camera`) a CAMERA_RGBD of 4x3 pixels (distinct values, one depth pixel 0, the
/// depth 5 ms after the colour, a distorted camera) every third state whose T_body_camera is
/// body_camera(). Returns the states written.
std::vector<kestrel::state_t> write_state_log(const std::filesystem::path& path, int n, bool with_camera);

}  // namespace kestrel::test
