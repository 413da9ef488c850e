#include "slam/slam_messages.h"

#include <algorithm>

#include "common/geometry/se3.h"
#include "common/transport/convert.h"

namespace kestrel::slam {

VoMotion motion_from_message(const kestrel::vo_update_t& m, const char* channel) {
  VoMotion motion;
  motion.utime = m.utime;
  motion.reference_utime = m.reference_utime;
  motion.ok = m.status == kestrel::vo_update_t::STATUS_OK;
  motion.new_reference = (m.flags & kestrel::vo_update_t::FLAG_NEW_REFERENCE) != 0;
  motion.T_body_camera = transport::from_message(m.T_body_camera, channel);
  if (motion.ok) {
    motion.T_reference_current = transport::from_message(m.T_reference_current, channel);
    motion.covariance = transport::covariance_from(m.covariance);
    motion.translation_floor_m = m.translation_floor;
    motion.rotation_floor_rad = m.rotation_floor;
  }
  return motion;
}

int64_t published_id(const Slam& slam, int64_t keyframe_index) {
  const int session = slam.keyframes().at(static_cast<size_t>(keyframe_index)).session;
  return slam.session_start_utime(session) + keyframe_index;
}

int64_t published_revision(const Slam& slam) {
  // The newest session with a keyframe, or this process's first frame when it has none yet (on
  // a saved map: after the map's revisions, which the flight that made it published).
  int64_t base = slam.first_frame_utime();
  if (!slam.keyframes().empty()) base = std::max(base, slam.session_start_utime(slam.keyframes().back().session));
  return base + slam.revision();
}

namespace {
// Keyframe k (its index in Slam::keyframes(), and vertex k of the graph) as published.
kestrel::slam_keyframe_t keyframe_message(const Slam& slam, size_t k) {
  const Keyframe& keyframe = slam.keyframes()[k];
  kestrel::slam_keyframe_t kf{};
  kf.id = published_id(slam, keyframe.id);
  kf.utime = keyframe.utime;
  kf.T_world_camera = transport::to_message(slam.graph().poses[k]);
  kf.T_camera_depth = transport::to_message(keyframe.T_camera_depth);
  return kf;
}
}  // namespace

kestrel::slam_graph_t graph_message(const Slam& slam) {
  kestrel::slam_graph_t m{};
  const auto& keyframes = slam.keyframes();
  const PoseGraph3d& graph = slam.graph();
  m.utime = keyframes.empty() ? 0 : keyframes.back().utime;
  m.revision = published_revision(slam);
  for (size_t k = 0; k < keyframes.size(); ++k) m.keyframes.push_back(keyframe_message(slam, k));
  m.num_keyframes = static_cast<int32_t>(m.keyframes.size());
  for (const auto& e : graph.edges) {
    kestrel::slam_edge_t edge{};
    edge.from_id = published_id(slam, graph.ids[static_cast<size_t>(e.from)]);
    edge.to_id = published_id(slam, graph.ids[static_cast<size_t>(e.to)]);
    edge.kind = e.kind == EdgeKind::kLoopClosure ? kestrel::slam_edge_t::KIND_LOOP_CLOSURE
                                                 : kestrel::slam_edge_t::KIND_ODOMETRY;
    edge.T_from_to = transport::to_message(e.measurement);
    m.edges.push_back(edge);
  }
  m.num_edges = static_cast<int32_t>(m.edges.size());
  return m;
}

kestrel::slam_graph_t unplaced_graph_message(const Slam& slam, size_t max_keyframes) {
  kestrel::slam_graph_t m{};
  m.revision = published_revision(slam);
  const auto& keyframes = slam.keyframes();
  const size_t first = keyframes.size() > max_keyframes ? keyframes.size() - max_keyframes : 0;
  for (size_t k = first; k < keyframes.size(); ++k) {
    if (slam.in_world(keyframes[k].id)) continue;
    m.keyframes.push_back(keyframe_message(slam, k));
    m.utime = m.keyframes.back().utime;
  }
  m.num_keyframes = static_cast<int32_t>(m.keyframes.size());
  m.num_edges = 0;
  return m;
}

Matrix6d body_covariance(const Eigen::Isometry3d& T_world_body, const Eigen::Isometry3d& T_body_camera,
                         const Matrix6d& camera_covariance) {
  // A right perturbation xi of T_world_camera moves T_world_body by Ad(T_body_camera) xi on the
  // right; pose_t wants the translation part in the world frame.
  Matrix6d J = se3::adjoint(T_body_camera);
  J.topRows<3>() = (T_world_body.linear() * J.topRows<3>()).eval();
  const Matrix6d covariance = J * camera_covariance * J.transpose();
  return 0.5 * (covariance + covariance.transpose());
}

Matrix6d anchor_covariance_at(const WorldAnchor& anchor, const Eigen::Isometry3d& T_world_body) {
  // The graph moved by the anchor's error: a left perturbation of the world, phi = R_anchor
  // dtheta_anchor, turning every pose about the anchor's position.
  const Eigen::Matrix3d R_anchor = anchor.T_world_body.linear();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.topRightCorner<3, 3>() = -so3::hat(T_world_body.translation() - anchor.T_world_body.translation()) * R_anchor;
  J.bottomRightCorner<3, 3>() = T_world_body.linear().transpose() * R_anchor;
  const Matrix6d covariance = J * anchor.covariance * J.transpose();
  return 0.5 * (covariance + covariance.transpose());
}

kestrel::slam_correction_t correction_message(const Slam& slam, double sigma_translation_m,
                                              double sigma_rotation_rad,
                                              const std::optional<FrameSinceKeyframe>& frame,
                                              const std::optional<WorldAnchor>& anchor) {
  const OdometryReference& reference = slam.reference();
  const Keyframe& kf = slam.keyframes().at(static_cast<size_t>(reference.keyframe_id));
  kestrel::slam_correction_t m{};
  m.utime = frame ? frame->utime : reference.utime;
  m.keyframe_id = published_id(slam, kf.id);
  m.graph_revision = published_revision(slam);
  // The camera in the reference frame, and in the reference's keyframe.
  const Eigen::Isometry3d T_reference_camera =
      frame ? reference.T_odom_camera.inverse() * frame->T_odom_camera : Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d T_keyframe_camera = reference.T_keyframe_camera * T_reference_camera;
  const Eigen::Isometry3d T_body_camera = frame ? frame->T_body_camera : reference.T_body_camera;
  const Eigen::Isometry3d T_world_body =
      slam.graph().poses.at(static_cast<size_t>(kf.id)) * T_keyframe_camera * T_body_camera.inverse();
  m.T_world_body = transport::to_message(T_world_body);
  // T_world_camera = T_world_keyframe * T_keyframe_reference * T_reference_camera: a right
  // perturbation of each factor is carried to the camera by the adjoint of the inverse of what
  // follows it (the keyframe's marginal, the re-anchoring's covariance), and the odometry's own adds.
  const Matrix6d A = se3::adjoint(T_keyframe_camera.inverse());
  const Matrix6d B = se3::adjoint(T_reference_camera.inverse());
  const Matrix6d odometry = (frame ? frame->odometry_covariance : Matrix6d::Zero()) +
                            B * reference.covariance * B.transpose();
  Matrix6d covariance = Matrix6d::Zero();
  if (const auto& marginal = slam.reference_marginal()) {
    covariance = body_covariance(T_world_body, T_body_camera, A * *marginal * A.transpose() + odometry);
  } else {
    covariance.diagonal().head<3>().setConstant(sigma_translation_m * sigma_translation_m);
    covariance.diagonal().tail<3>().setConstant(sigma_rotation_rad * sigma_rotation_rad);
    covariance += body_covariance(T_world_body, T_body_camera, odometry);
  }
  if (anchor) covariance += anchor_covariance_at(*anchor, T_world_body);
  transport::covariance_to(covariance, m.covariance);
  return m;
}

}  // namespace kestrel::slam
