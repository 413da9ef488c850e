#include "ros/exporter.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"
#include "ros/ros_convert.h"

namespace kestrel::ros1 {

namespace {

using Matrix15d = Eigen::Matrix<double, 15, 15>;

// state_t's error state (lcmtypes/state_t.lcm, docs/architecture.md "Covariances"):
// [dp (world); dv (world); dtheta (body, R = R_est * Exp(dtheta)); d_gyro_bias; d_accel_bias].
constexpr int kP = 0, kV = 3, kTheta = 6, kBg = 9, kNav = 15;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

void to_msg(const Eigen::Isometry3d& T, geometry_msgs::Pose& p) {
  const Eigen::Quaterniond q(T.linear());
  p.position.x = T.translation().x();
  p.position.y = T.translation().y();
  p.position.z = T.translation().z();
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
}

void to_msg(const Eigen::Isometry3d& T, geometry_msgs::Transform& t) {
  const Eigen::Quaterniond q(T.linear());
  t.translation.x = T.translation().x();
  t.translation.y = T.translation().y();
  t.translation.z = T.translation().z();
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
}

// A bag takes times from ros::TIME_MIN (1 ns) to 2^32 s (ros::Time's unsigned seconds).
ros::Time stamp_of(int64_t utime, const std::string& what) {
  constexpr int64_t kLast = (int64_t{1} << 32) * 1000000 - 1;
  if (utime <= 0 || utime > kLast)
    throw InputError(what + ": utime " + std::to_string(utime) + " is outside a ROS bag's times (1 us to 2^32 s)");
  return to_ros_time(utime);
}

geometry_msgs::TransformStamped transform(const Eigen::Isometry3d& T, const ros::Time& stamp, const std::string& parent,
                                          const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  to_msg(T, t.transform);
  return t;
}

}  // namespace

nav_msgs::Odometry odometry_from_state(const kestrel::state_t& s, const std::string& world_frame,
                                       const std::string& body_frame, const std::string& what) {
  // from_message checks the pose (finite, a unit quaternion) and normalises a slightly
  // non-unit one; the message keeps the normalised quaternion.
  const Eigen::Isometry3d T = transport::from_message(s.T_world_body, what.c_str());
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d v_world(s.velocity[0], s.velocity[1], s.velocity[2]);
  const Eigen::Vector3d v_body = R.transpose() * v_world;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v_world[i]) || !std::isfinite(s.angular_velocity[i]))
      throw InputError(what + ": a non-finite velocity");

  nav_msgs::Odometry o;
  o.header.stamp = stamp_of(s.utime, what);
  o.header.seq = static_cast<uint32_t>(s.seq);
  o.header.frame_id = world_frame;
  o.child_frame_id = body_frame;
  to_msg(T, o.pose.pose);
  // nav_msgs/Odometry: the twist is in child_frame_id's axes (the body's).
  o.twist.twist.linear.x = v_body.x();
  o.twist.twist.linear.y = v_body.y();
  o.twist.twist.linear.z = v_body.z();
  o.twist.twist.angular.x = s.angular_velocity[0];
  o.twist.twist.angular.y = s.angular_velocity[1];
  o.twist.twist.angular.z = s.angular_velocity[2];

  // Covariances. ROS's are row-major 6x6 over (x, y, z, rotation about x, y, z): the pose's in
  // header.frame_id (the world; rotations about the world's axes, R = Exp(dphi) * R_est, as
  // robot_localization and rviz's "fixed frame" orientation read them), the twist's in
  // child_frame_id (the body). With the state's error x = [dp; dv; dtheta; d_bg; d_ba], to
  // first order:
  //   pose  [dp; dphi] = [dp; R * dtheta]                         (dp is already the world's)
  //   twist [dv_body; domega] = [R^T dv + [v_body]x dtheta; -d_bg] (v_body = R^T v_world, and
  //         R^T = Exp(-dtheta) R_est^T; omega = gyro - b_g)
  // so each is J * P * J^T with J taking the blocks above. The twist's angular rows are the
  // gyro bias's uncertainty only (the gyro's own noise is not in the state), and are left
  // zero (ROS: unknown) for FILTER_VISUAL_ONLY, whose bias block is a constant prior and whose
  // angular velocity is the VO's. The accelerometer bias block has no place in Odometry. A
  // STATE with another cov_dim than 15 leaves both covariances zero.
  if (s.cov_dim == kNav && s.covariance.size() == static_cast<size_t>(kNav)) {
    Matrix15d P;
    for (int r = 0; r < kNav; ++r) {
      if (s.covariance[r].size() != static_cast<size_t>(kNav)) return o;
      for (int c = 0; c < kNav; ++c) P(r, c) = s.covariance[r][c];
    }
    Eigen::Matrix<double, 6, 15> Jp = Eigen::Matrix<double, 6, 15>::Zero();
    Jp.block<3, 3>(0, kP).setIdentity();
    Jp.block<3, 3>(3, kTheta) = R;
    Eigen::Matrix<double, 6, 15> Jt = Eigen::Matrix<double, 6, 15>::Zero();
    Jt.block<3, 3>(0, kV) = R.transpose();
    Jt.block<3, 3>(0, kTheta) = skew(v_body);
    if (s.filter != kestrel::state_t::FILTER_VISUAL_ONLY) Jt.block<3, 3>(3, kBg) = -Eigen::Matrix3d::Identity();
    const Eigen::Matrix<double, 6, 6> pose_cov = Jp * P * Jp.transpose();
    const Eigen::Matrix<double, 6, 6> twist_cov = Jt * P * Jt.transpose();
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) {
        o.pose.covariance[static_cast<size_t>(r * 6 + c)] = pose_cov(r, c);
        o.twist.covariance[static_cast<size_t>(r * 6 + c)] = twist_cov(r, c);
      }
  }
  return o;
}


Exporter::Exporter(ExportOptions options, RosSink& sink, ExportStats& stats)
    : o_(std::move(options)), sink_(sink), stats_(stats) {}

void Exporter::reset() {
  chain_ = eval::VoChain{};
  last_vo_utime_.reset();
  camera_written_ = false;
}

// The map's occupied cells (and free ones with map_free) as clouds and the occupied as cubes,
// in the world frame at the map's utime; latched: rviz started later still shows the map.
void Exporter::map(const kestrel::octomap_t& m, const std::string& what) {
  const ros::Time t = stamp_of(m.utime, what);
  const MapCells cells = map_cells(m, o_.map_free, what);
  write(topic::kMapOccupied, t, point_cloud(cells.occupied, o_.world_frame, t), /*latched=*/true);
  if (o_.map_free) write(topic::kMapFree, t, point_cloud(cells.free, o_.world_frame, t), /*latched=*/true);
  write(topic::kMapVoxels, t, voxel_markers(cells, o_.world_frame, t), /*latched=*/true);
}

void Exporter::state(const kestrel::state_t& s, const std::string& what) {
  const nav_msgs::Odometry odom = odometry_from_state(s, o_.world_frame, o_.body_frame, what);
  write(topic::kOdom, odom.header.stamp, odom);
  tf2_msgs::TFMessage tf;
  geometry_msgs::TransformStamped t;
  t.header = odom.header;
  t.child_frame_id = o_.body_frame;
  t.transform.translation.x = odom.pose.pose.position.x;
  t.transform.translation.y = odom.pose.pose.position.y;
  t.transform.translation.z = odom.pose.pose.position.z;
  t.transform.rotation = odom.pose.pose.orientation;
  tf.transforms.push_back(t);
  write(topic::kTf, odom.header.stamp, tf);
}

// The VO's motions chained into the camera's poses by eval's VoChain (tools/eval/vo_chain.h:
// its rules for a failed frame or an unknown reference), the step made from the message as
// eval's log reader makes it. Each frame the chain gives a pose is one Odometry of the
// camera in the VO's world; no covariance (the chain's is not accumulated) and no twist.
void Exporter::vo(const kestrel::vo_update_t& m, const std::string& what) {
  if (last_vo_utime_ && m.utime <= *last_vo_utime_) {
    ++stats_.vo_out_of_order;
    return;
  }
  last_vo_utime_ = m.utime;
  mount(m.T_body_camera, m.utime, what);
  eval::VoStep step;
  step.utime = m.utime;
  step.reference_utime = m.reference_utime;
  step.no_reference = m.status == kestrel::vo_update_t::STATUS_NO_REFERENCE;
  if (m.status == kestrel::vo_update_t::STATUS_OK) {
    step.T_reference_current = transport::from_message(m.T_reference_current, what.c_str());
    step.valid = true;
  }
  const size_t before = chain_.trajectory().size();
  chain_.add(step);
  stats_.vo_without_estimate = static_cast<int64_t>(chain_.without_estimate());
  if (chain_.trajectory().size() == before) return;
  nav_msgs::Odometry o;
  o.header.stamp = stamp_of(m.utime, what);
  o.header.seq = static_cast<uint32_t>(m.seq);
  o.header.frame_id = o_.vo_frame;
  o.child_frame_id = o_.camera_frame;
  to_msg(chain_.trajectory().poses().back().T, o.pose.pose);
  write(topic::kVo, o.header.stamp, o);
}

void Exporter::truth(const kestrel::ground_truth_t& m, const std::string& what) {
  geometry_msgs::PoseStamped p;
  p.header.stamp = stamp_of(m.utime, what);
  p.header.frame_id = o_.truth_frame;
  to_msg(transport::from_message(m.T_world_frame, what.c_str()), p.pose);
  write(topic::kGroundTruth, p.header.stamp, p);
  const std::string of = m.frame == kestrel::ground_truth_t::FRAME_CAMERA ? "camera" : "body";
  if (!stats_.truth_of.empty() && stats_.truth_of != of)
    throw InputError(what + ": the ground truth is of the " + of + " here, of the " + stats_.truth_of + " before");
  stats_.truth_of = of;
}

// Each revision of the graph as one Path of its keyframes' optimised camera poses, in time
// order, in the world frame (SLAM's world, which the estimator's STATE takes on); the
// message's stamp is the newest keyframe's utime. Its loop closures go to /kestrel/slam/loops
// as one LINE_LIST marker, a segment between the two keyframes' cameras per edge (an edge whose
// keyframe the graph no longer holds is left out); a graph without one sends DELETEALL, so that
// rviz drops the loops of a graph SLAM restarted.
void Exporter::graph(const kestrel::slam_graph_t& g, const std::string& what) {
  nav_msgs::Path path;
  path.header.stamp = stamp_of(g.utime, what);
  path.header.seq = static_cast<uint32_t>(g.revision);
  path.header.frame_id = o_.world_frame;
  std::vector<const kestrel::slam_keyframe_t*> keyframes;
  for (const auto& k : g.keyframes) keyframes.push_back(&k);
  std::stable_sort(keyframes.begin(), keyframes.end(), [](const auto* a, const auto* b) { return a->utime < b->utime; });
  for (const auto* k : keyframes) {
    geometry_msgs::PoseStamped p;
    p.header.stamp = stamp_of(k->utime, what);
    p.header.frame_id = o_.world_frame;
    to_msg(transport::from_message(k->T_world_camera, what.c_str()), p.pose);
    path.poses.push_back(p);
  }
  write(topic::kKeyframes, path.header.stamp, path, /*latched=*/true);

  std::map<int64_t, geometry_msgs::Point> camera_of;
  for (size_t i = 0; i < keyframes.size(); ++i) camera_of[keyframes[i]->id] = path.poses[i].pose.position;
  visualization_msgs::Marker loops;
  loops.header = path.header;
  loops.ns = "loops";
  loops.id = 0;
  loops.pose.orientation.w = 1.0;
  loops.type = visualization_msgs::Marker::LINE_LIST;
  loops.scale.x = 0.02;  // line width, metres
  loops.color.r = 1.0f;
  loops.color.g = 0.8f;
  loops.color.a = 1.0f;
  for (const kestrel::slam_edge_t& e : g.edges) {
    if (e.kind != kestrel::slam_edge_t::KIND_LOOP_CLOSURE) continue;
    const auto from = camera_of.find(e.from_id), to = camera_of.find(e.to_id);
    if (from == camera_of.end() || to == camera_of.end()) continue;
    loops.points.push_back(from->second);
    loops.points.push_back(to->second);
  }
  loops.action = loops.points.empty() ? visualization_msgs::Marker::DELETEALL : visualization_msgs::Marker::ADD;
  visualization_msgs::MarkerArray a;
  a.markers.push_back(loops);
  write(topic::kLoops, path.header.stamp, a, /*latched=*/true);
}

// The planner's waypoints (x, y, z, yaw) as a Path in the world frame, the body level (roll
// and pitch zero); a plan without a path (no path, no map, ...) is an empty Path, which
// clears the last one in rviz.
void Exporter::plan(const kestrel::plan_t& m, const std::string& what) {
  nav_msgs::Path path;
  path.header.stamp = stamp_of(m.utime, what);
  path.header.seq = static_cast<uint32_t>(m.request_id);
  path.header.frame_id = o_.world_frame;
  if (m.status == kestrel::plan_t::STATUS_OK) {
    for (const auto& w : m.waypoints) {
      if (w.size() != 4 || !std::isfinite(w[0]) || !std::isfinite(w[1]) || !std::isfinite(w[2]) || !std::isfinite(w[3]))
        throw InputError(what + ": a waypoint that is not four finite numbers");
      geometry_msgs::PoseStamped p;
      p.header = path.header;
      p.pose.position.x = w[0];
      p.pose.position.y = w[1];
      p.pose.position.z = w[2];
      p.pose.orientation.z = std::sin(w[3] / 2);
      p.pose.orientation.w = std::cos(w[3] / 2);
      path.poses.push_back(p);
    }
  }
  write(topic::kPlan, path.header.stamp, path, /*latched=*/true);
}

// A frame decoded by kestrel's RGB-D decoder (JPEG, zstd): the colour image as rgb8 at
// utime, the depth as 16UC1 millimetres (0 = no reading, the depth_image_proc convention)
// at depth_utime, both in the camera frame, and the CameraInfo at utime: K, plumb_bob D
// (k1 k2 p1 p2 k3), R = I, P = [K | 0] (the images are as the camera gave them, unrectified).
void Exporter::images(const kestrel::rgbd_frame_t& m, const std::string& what) {
  const RgbdFrame f = transport::decode_rgbd(m, what.c_str());
  const ros::Time t = stamp_of(f.utime, what);
  if (!f.rgb.empty()) {
    sensor_msgs::Image image;
    image.header.stamp = t;
    image.header.seq = static_cast<uint32_t>(f.seq);
    image.header.frame_id = o_.camera_frame;
    image.width = static_cast<uint32_t>(f.rgb.cols);
    image.height = static_cast<uint32_t>(f.rgb.rows);
    image.encoding = "rgb8";
    image.step = image.width * 3;
    image.data.resize(static_cast<size_t>(image.step) * image.height);
    for (int r = 0; r < f.rgb.rows; ++r)
      std::copy_n(f.rgb.ptr<uint8_t>(r), image.step, image.data.data() + static_cast<size_t>(r) * image.step);
    write(topic::kColour, t, image);
  }
  if (!f.depth_mm.empty()) {
    sensor_msgs::Image depth;
    depth.header.stamp = stamp_of(f.depth_utime, what);
    depth.header.seq = static_cast<uint32_t>(f.seq);
    depth.header.frame_id = o_.camera_frame;
    depth.width = static_cast<uint32_t>(f.depth_mm.cols);
    depth.height = static_cast<uint32_t>(f.depth_mm.rows);
    depth.encoding = "16UC1";
    depth.is_bigendian = 0;
    depth.step = depth.width * 2;
    depth.data.resize(static_cast<size_t>(depth.step) * depth.height);
    for (int r = 0; r < f.depth_mm.rows; ++r) {
      const uint16_t* row = f.depth_mm.ptr<uint16_t>(r);
      uint8_t* out = depth.data.data() + static_cast<size_t>(r) * depth.step;
      for (int c = 0; c < f.depth_mm.cols; ++c) {  // little-endian, whatever the host
        out[2 * c] = static_cast<uint8_t>(row[c] & 0xff);
        out[2 * c + 1] = static_cast<uint8_t>(row[c] >> 8);
      }
    }
    write(topic::kDepth, depth.header.stamp, depth);
  }
  sensor_msgs::CameraInfo info;
  info.header.stamp = t;
  info.header.seq = static_cast<uint32_t>(f.seq);
  info.header.frame_id = o_.camera_frame;
  info.width = static_cast<uint32_t>(f.camera.width);
  info.height = static_cast<uint32_t>(f.camera.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(f.camera.distortion.begin(), f.camera.distortion.end());
  info.K = {f.camera.fx, 0, f.camera.cx, 0, f.camera.fy, f.camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {f.camera.fx, 0, f.camera.cx, 0, 0, f.camera.fy, f.camera.cy, 0, 0, 0, 1, 0};
  write(topic::kCameraInfo, t, info);
}

// base_link -> camera, once, on /tf_static (latched by `rosbag play`, read by rviz as tf),
// from the first CAMERA_RGBD's or VO_UPDATE's T_body_camera (the system's output logs hold
// no frames, and the VO copies the mounting into each update).
void Exporter::camera(const kestrel::rgbd_frame_t& f, const std::string& what) {
  mount(f.camera.T_body_camera, f.utime, what);
  if (o_.images) images(f, what);
}

void Exporter::mount(const kestrel::pose3_t& T_body_camera_message, int64_t utime, const std::string& what) {
  if (camera_written_) return;
  const Eigen::Isometry3d T_body_camera = transport::from_message(T_body_camera_message, what.c_str());
  tf2_msgs::TFMessage tf;
  const ros::Time t = stamp_of(utime, what);
  tf.transforms.push_back(transform(T_body_camera, t, o_.body_frame, o_.camera_frame));
  write(topic::kTfStatic, t, tf, /*latched=*/true);
  camera_written_ = true;
}

}  // namespace kestrel::ros1
