#include "sim_fixture.h"

#include <map>
#include <memory>
#include <string>

#include "drivers/sim/world_builder.h"
#include "drivers/sim/world_catalog.h"

namespace kestrel::sim::test {

const World& plane_world(bool with_box) {
  static std::map<bool, std::unique_ptr<World>> worlds;
  auto& w = worlds[with_box];
  if (!w) {
    WorldBuilder b(with_box ? "plane and box" : "plane");
    MaterialSpec plaster;
    plaster.name = "plaster";
    plaster.pattern = "concrete";
    plaster.color = {0.85, 0.85, 0.82};
    const int m = b.add_material(plaster);
    b.set_bounds(Eigen::AlignedBox3d(Eigen::Vector3d(-6, -6, -1), Eigen::Vector3d(6, 6, 4)));
    b.add_wall(m, {3.0, -4.0}, {3.0, 4.0}, -1.0, 4.0, 1.0);  // seen from its left: -x
    if (with_box) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = Eigen::Vector3d(2.0, 0.3, 1.4);
      T.linear() = Eigen::AngleAxisd(20.0 * 3.14159265358979 / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      b.add_box(m, T, Eigen::Vector3d::Constant(0.25), 1.0);
    }
    w = std::make_unique<World>(b.build());
  }
  return *w;
}

const World& builtin(const char* name) {
  static std::map<std::string, std::unique_ptr<World>> worlds;
  auto& w = worlds[name];
  if (!w) w = std::make_unique<World>(load_world(name));
  return *w;
}

Eigen::Isometry3d look(const Eigen::Vector3d& position, double yaw, double pitch) {
  Eigen::Matrix3d R_body_optical;
  R_body_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix() * R_body_optical;
  T.translation() = position;
  return T;
}

CameraOptions exact_camera() {
  CameraOptions o;
  o.depth.noise = false;
  o.rgb.noise = false;
  return o;
}

// RK4 over pairs of samples: k, k+1, k+2 are the start, middle and end of a step of 2 dt.
Integrated integrate(const Flight& flight, ImuSimulator& imu, double seconds) {
  const double dt = 1.0 / imu.options().rate_hz;
  const MotionState s0 = flight.state(0.0);
  Integrated x{Eigen::Quaterniond(s0.T_world_body.linear()), s0.v_world, s0.T_world_body.translation()};
  const Eigen::Vector3d g(0, 0, -kGravity);
  struct Rate {
    Eigen::Vector4d dq;
    Eigen::Vector3d dv, dp;
  };
  auto f = [&](const Eigen::Quaterniond& q, const Eigen::Vector3d& v, const ImuSample& m) {
    const Eigen::Quaterniond w(0, m.gyro.x(), m.gyro.y(), m.gyro.z());
    const Eigen::Quaterniond qd = q * w;
    return Rate{0.5 * qd.coeffs(), q.normalized() * m.accel + g, v};
  };
  ImuSample a = imu.next();
  const int steps = static_cast<int>(std::lround(seconds / (2 * dt)));
  for (int k = 0; k < steps; ++k) {
    const ImuSample b = imu.next(), c = imu.next();
    const double h = 2 * dt;
    auto add = [](const Integrated& s, const Rate& r, double step) {
      Integrated out;
      out.q.coeffs() = s.q.coeffs() + step * r.dq;
      out.v = s.v + step * r.dv;
      out.p = s.p + step * r.dp;
      return out;
    };
    const Rate k1 = f(x.q, x.v, a);
    const Integrated x2 = add(x, k1, h / 2);
    const Rate k2 = f(x2.q, x2.v, b);
    const Integrated x3 = add(x, k2, h / 2);
    const Rate k3 = f(x3.q, x3.v, b);
    const Integrated x4 = add(x, k3, h);
    const Rate k4 = f(x4.q, x4.v, c);
    x.q.coeffs() += h / 6 * (k1.dq + 2 * k2.dq + 2 * k3.dq + k4.dq);
    x.q.normalize();
    x.v += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    x.p += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    a = c;
  }
  return x;
}

}  // namespace kestrel::sim::test
