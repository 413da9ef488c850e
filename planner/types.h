#pragma once
// The planner's vocabulary: a configuration q = (x, y, z, yaw) in the world frame (metres,
// radians) and the 4 x 4 covariance of the belief over it. The belief's error state is
// [dx, dy, dz, dyaw] (world frame, additive), the same order as the configuration.

#include <Eigen/Core>
#include <random>

namespace kestrel::planner {

using Config = Eigen::Vector4d;   ///< x, y, z (m), yaw (rad)
using Mat4 = Eigen::Matrix4d;     ///< covariance / information of the belief
using Rng = std::mt19937_64;      ///< every random draw goes through a seeded engine

/// Position part of a configuration.
inline Eigen::Vector3d position(const Config& q) { return q.head<3>(); }

}  // namespace kestrel::planner
