#include "estimator/nav_state.h"

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"

namespace kestrel::estimator {

Eigen::Isometry3d NavState::T_world_body() const { return se3::make(R_world_body, p_world_body); }

bool NavState::all_finite() const {
  return p_world_body.allFinite() && v_world_body.allFinite() && R_world_body.allFinite() &&
         gyro_bias.allFinite() && accel_bias.allFinite();
}

NavState boxplus(const NavState& x, const Eigen::Ref<const Vector15d>& dx) {
  NavState out;
  out.p_world_body = x.p_world_body + dx.segment<3>(idx::kP);
  out.v_world_body = x.v_world_body + dx.segment<3>(idx::kV);
  out.R_world_body = x.R_world_body * so3::exp(dx.segment<3>(idx::kTheta));
  out.gyro_bias = x.gyro_bias + dx.segment<3>(idx::kBg);
  out.accel_bias = x.accel_bias + dx.segment<3>(idx::kBa);
  return out;
}

Vector15d boxminus(const NavState& a, const NavState& b) {
  Vector15d dx;
  dx.segment<3>(idx::kP) = a.p_world_body - b.p_world_body;
  dx.segment<3>(idx::kV) = a.v_world_body - b.v_world_body;
  dx.segment<3>(idx::kTheta) = so3::log(b.R_world_body.transpose() * a.R_world_body);
  dx.segment<3>(idx::kBg) = a.gyro_bias - b.gyro_bias;
  dx.segment<3>(idx::kBa) = a.accel_bias - b.accel_bias;
  return dx;
}

}  // namespace kestrel::estimator
