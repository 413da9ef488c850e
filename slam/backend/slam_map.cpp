#include "slam/backend/slam_map.h"

#include <string>

#include "common/error.h"
#include "common/geometry/se3.h"

namespace kestrel::slam {

void check_map(const SlamMap& map, const std::string& what) {
  auto fail = [&what](const std::string& why) { throw InputError(what + ": " + why); };
  const size_t n = map.keyframes.size();
  if (map.graph.poses.size() != n || map.graph.ids.size() != n || map.graph.fixed.size() != n) {
    fail(std::to_string(n) + " keyframes but " + std::to_string(map.graph.poses.size()) + " graph vertices");
  }
  if (map.gate_information.size() != map.graph.edges.size()) fail("the loop gate's model does not cover every edge");
  if (!map.vocabulary) fail("no vocabulary");
  if (map.sessions < (n > 0 ? 1 : 0)) fail("keyframes but no session");
  for (size_t k = 0; k < n; ++k) {
    const Keyframe& kf = map.keyframes[k];
    const std::string name = "keyframe " + std::to_string(k);
    if (kf.id != static_cast<int64_t>(k) || map.graph.ids[k] != static_cast<int64_t>(k)) fail(name + " is not vertex " + name);
    if (kf.session < 0 || kf.session >= map.sessions) fail(name + " has session " + std::to_string(kf.session));
    for (const Eigen::Isometry3d* T : {&kf.T_odom_camera, &kf.T_body_camera, &kf.T_camera_depth, &map.graph.poses[k]}) {
      if (!se3::is_valid(*T, 1e-6)) fail(name + ": a pose is not a rigid transform");
    }
    const FrameFeatures& f = kf.features;
    if (kf.thinned && f.size() != 0) fail(name + " is thinned but has features");
    if (f.points.size() != f.size() || static_cast<size_t>(f.descriptors.rows) != f.size() ||
        (f.size() > 0 && (f.descriptors.cols != 32 || f.descriptors.type() != CV_8UC1))) {
      fail(name + ": keypoints, descriptors and points differ in number or shape");
    }
    for (const Eigen::Vector3d& p : f.points) {
      if (!std::isnan(p.z()) && !p.allFinite()) fail(name + ": a point is not finite");
    }
  }
  try {
    check_graph(map.graph);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  for (const auto& e : map.graph.edges) {
    if (!se3::is_valid(e.measurement, 1e-6)) fail("an edge's measurement is not a rigid transform");
  }
  for (const Matrix6d& info : map.gate_information) {
    if (!info.allFinite()) fail("the loop gate's model is not finite");
  }
}

}  // namespace kestrel::slam
