#include "drivers/sim/world_builder.h"

#include <map>
#include <stdexcept>

namespace kestrel::sim {
namespace {

bool finite(const Eigen::Vector2d& v) { return v.allFinite(); }

}  // namespace

WorldBuilder::WorldBuilder(std::string name) : name_(std::move(name)) {}

int WorldBuilder::add_material(const MaterialSpec& spec) {
  if (material_index(spec.name) >= 0) throw std::invalid_argument("material '" + spec.name + "' defined twice");
  if (!is_pattern(spec.pattern)) throw std::invalid_argument("unknown material pattern '" + spec.pattern + "'");
  materials_.push_back(spec);
  return static_cast<int>(materials_.size()) - 1;
}

int WorldBuilder::material_index(const std::string& name) const {
  for (size_t i = 0; i < materials_.size(); ++i)
    if (materials_[i].name == name) return static_cast<int>(i);
  return -1;
}

void WorldBuilder::check_material(int material) const {
  if (material < 0 || material >= static_cast<int>(materials_.size()))
    throw std::invalid_argument("no material with index " + std::to_string(material));
}

int WorldBuilder::add_surface(Surface s, SurfaceKind kind, int material, double texture) {
  check_material(material);
  if (!(s.width > 0) || !(s.height > 0) || !s.origin.allFinite() || !(texture >= 0))
    throw std::invalid_argument("degenerate surface in world '" + name_ + "'");
  s.kind = kind;
  s.material = material;
  s.texture = texture;
  s.id = static_cast<int>(surfaces_.size());
  surfaces_.push_back(s);
  return s.id;
}

int WorldBuilder::add_floor(int material, const Eigen::AlignedBox2d& area, double z, double texture) {
  const Eigen::Vector2d size = area.sizes();
  return add_surface(make_rectangle({area.min().x(), area.min().y(), z}, Eigen::Vector3d::UnitX(),
                                    Eigen::Vector3d::UnitY(), size.x(), size.y()),
                     SurfaceKind::kFloor, material, texture);
}

int WorldBuilder::add_ceiling(int material, const Eigen::AlignedBox2d& area, double z, double texture) {
  const Eigen::Vector2d size = area.sizes();
  return add_surface(make_rectangle({area.min().x(), area.max().y(), z}, Eigen::Vector3d::UnitX(),
                                    -Eigen::Vector3d::UnitY(), size.x(), size.y()),
                     SurfaceKind::kCeiling, material, texture);
}

int WorldBuilder::add_wall(int material, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1,
                           double texture, SurfaceKind kind) {
  if (!finite(a) || !finite(b) || (b - a).norm() <= 0 || !(z1 > z0))
    throw std::invalid_argument("degenerate wall in world '" + name_ + "'");
  const Eigen::Vector2d d = (a - b).normalized();
  return add_surface(make_rectangle({b.x(), b.y(), z0}, {d.x(), d.y(), 0.0}, Eigen::Vector3d::UnitZ(),
                                    (b - a).norm(), z1 - z0),
                     kind, material, texture);
}

int WorldBuilder::add_box(int material, const Eigen::Isometry3d& T, const Eigen::Vector3d& h, double texture) {
  if (!(h.minCoeff() > 0) || !h.allFinite() || !T.matrix().allFinite())
    throw std::invalid_argument("degenerate box in world '" + name_ + "'");
  Box box;
  box.T_world_box = T;
  box.half_extent = h;
  const int index = static_cast<int>(boxes_.size());
  const Eigen::Matrix3d& R = T.linear();
  const Eigen::Vector3d x = R.col(0), y = R.col(1), z = R.col(2);
  auto at = [&](double a, double b, double c) -> Eigen::Vector3d { return T * Eigen::Vector3d(a, b, c); };
  // Faces in Box::faces order (+x, -x, +y, -y, +z, -z); s x t is the outward normal and
  // t points up on the side faces.
  const Surface faces[6] = {
      make_rectangle(at(h.x(), -h.y(), -h.z()), y, z, 2 * h.y(), 2 * h.z()),
      make_rectangle(at(-h.x(), h.y(), -h.z()), -y, z, 2 * h.y(), 2 * h.z()),
      make_rectangle(at(h.x(), h.y(), -h.z()), -x, z, 2 * h.x(), 2 * h.z()),
      make_rectangle(at(-h.x(), -h.y(), -h.z()), x, z, 2 * h.x(), 2 * h.z()),
      make_rectangle(at(-h.x(), -h.y(), h.z()), x, y, 2 * h.x(), 2 * h.y()),
      make_rectangle(at(-h.x(), h.y(), -h.z()), x, -y, 2 * h.x(), 2 * h.y()),
  };
  for (int f = 0; f < 6; ++f) {
    Surface s = faces[f];
    s.box = index;
    box.faces[f] = add_surface(s, SurfaceKind::kBoxFace, material, texture);
  }
  boxes_.push_back(box);
  return index;
}

int WorldBuilder::add_slab(int material, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1,
                           double thickness, double texture) {
  if (!finite(a) || !finite(b) || (b - a).norm() <= 0 || !(z1 > z0) || !(thickness > 0))
    throw std::invalid_argument("degenerate wall in world '" + name_ + "'");
  const Eigen::Vector2d d = b - a;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::atan2(d.y(), d.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << 0.5 * (a + b), 0.5 * (z0 + z1);
  return add_box(material, T, {0.5 * d.norm(), 0.5 * thickness, 0.5 * (z1 - z0)}, texture);
}

World WorldBuilder::build(WorldParts parts) {
  World w;
  w.name_ = name_;
  w.source_ = source_;
  if (bounds_) {
    w.bounds_ = *bounds_;
  } else {
    for (const Surface& s : surfaces_)
      for (const auto& c : s.corners()) w.bounds_.extend(c);
  }
  if (w.bounds_.isEmpty()) throw std::invalid_argument("world '" + name_ + "' has no extent");
  const Eigen::Vector3d centre = w.bounds_.center();
  w.start_ = start_ ? *start_ : Eigen::Vector4d(centre.x(), centre.y(), w.bounds_.min().z() + 1.2, 0.0);
  w.index_ = CollisionIndex(surfaces_, boxes_);
  if (parts == WorldParts::kAll) add_appearance(w);
  w.materials_ = std::move(materials_);
  w.surfaces_ = std::move(surfaces_);
  w.boxes_ = std::move(boxes_);
  w.lights_ = std::move(lights_);
  w.free_mask_ = std::move(free_mask_);
  materials_.clear();
  surfaces_.clear();
  boxes_.clear();
  lights_.clear();
  return w;
}

void WorldBuilder::add_appearance(World& w) const {
  w.looks_ = make_looks(surfaces_, materials_, seed_);
  compute_shade_maps(w.looks_, surfaces_, lights_, w.index_, lighting_, seed_);
  // Tiled surfaces of one material and density share a texture: measure each pair once.
  std::map<std::pair<const MipTexture*, float>, double> measured;
  for (SurfaceLook& look : w.looks_) {
    const auto key = std::make_pair(look.texture.get(), look.detail);
    auto it = measured.find(key);
    if (it == measured.end()) it = measured.emplace(key, measure_feature_density(look)).first;
    look.features_per_m2 = it->second;
  }
  w.wear_ = make_wear_texture(seed_);
}

}  // namespace kestrel::sim
