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

}  // namespace kestrel::sim::test
