// Messages off the bus, each decoded as its subscriber's Node decodes it and handed to the
// conversion the subscribing process runs first; and LCM log files, read as replay reads them.

#include <Eigen/Geometry>
#include <chrono>
#include <cstring>
#include <optional>

#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "control/follower_node.h"
#include "drivers/sim/messages.h"
#include "estimator/messages.h"
#include "fuzz/examples.h"
#include "fuzz/groups.h"
#include "kestrel/camera_info_t.hpp"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/pose3_t.hpp"
#include "kestrel/pose_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/rejection_counts_t.hpp"
#include "kestrel/rejection_reason_t.hpp"
#include "kestrel/replay_ack_t.hpp"
#include "kestrel/replay_control_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "kestrel/slam_edge_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/slam_keyframe_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "mapper/keyframe_journal.h"
#include "mapper/octree_io.h"
#include "mapper/voxel_map.h"
#include "planner/planner_messages.h"
#include "slam/slam_messages.h"
#include "tools/launch/health.h"

namespace kestrel::fuzz {
namespace {

using transport::decode_message;
using transport::encode_message;

// ---- Decoding, the same for every type ----------------------------------------------------

// Decodes as Node::subscribe does, checks that what was decoded encodes to bytes that decode
// to the same bytes again (a decoder that keeps a field it cannot write back would differ),
// then runs the subscriber's conversion.
template <class Msg, void (*Convert)(const Msg&)>
bool run_message(const uint8_t* data, size_t size) {
  return accepted([&] {
    const Msg m = decode_message<Msg>(data, size, "FUZZ");
    const Bytes once = encode_message(m);
    const Bytes twice = encode_message(decode_message<Msg>(once.data(), once.size(), "FUZZ"));
    if (once != twice) defect(Msg::getTypeName(), "a decoded message encodes differently the second time");
    Convert(m);
  });
}

template <class Msg, std::vector<Msg> (*Examples)()>
std::vector<Bytes> encoded() {
  std::vector<Bytes> out;
  for (const Msg& m : Examples()) out.push_back(encode_message(m));
  return out;
}

template <class Msg>
void decode_only(const Msg&) {}

kestrel::pose3_t pose(double x, double y, double z, double yaw = 0.3) {
  return transport::to_message(Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

void set_identity_covariance(double (&c)[36], double variance) {
  for (int i = 0; i < 36; ++i) c[i] = i % 7 == 0 ? variance : 0.0;
}

// ---- Each type's subscriber -----------------------------------------------------------------

void convert_camera(const kestrel::camera_info_t& m) {
  transport::from_message(m, "CAMERA_INFO");
  transport::from_message(m.T_body_camera, "CAMERA_INFO");
}
std::vector<kestrel::camera_info_t> camera_examples() {
  return {transport::to_message(small_camera(64, 48), Eigen::Isometry3d::Identity()),
          transport::to_message(PinholeCamera::vga(525, 525, 319.5, 239.5), Eigen::Isometry3d(Eigen::Translation3d(0.1, 0, 0)))};
}

void convert_ground_truth(const kestrel::ground_truth_t& m) {
  transport::from_message(m.T_world_frame, "GROUND_TRUTH");
}
std::vector<kestrel::ground_truth_t> ground_truth_examples() {
  kestrel::ground_truth_t g{};
  g.utime = 1000000;
  g.T_world_frame = pose(1, 2, 1.5);
  g.fields = kestrel::ground_truth_t::HAS_VELOCITY;
  g.velocity[0] = 0.5;
  return {g};
}

void convert_imu(const kestrel::imu_t& m) { estimator::imu_from_message(m, "IMU"); }
std::vector<kestrel::imu_t> imu_examples() {
  kestrel::imu_t m{};
  m.utime = 1000000;
  m.seq = 7;
  m.fields = kestrel::imu_t::HAS_GYRO | kestrel::imu_t::HAS_ACCEL;
  m.angular_velocity[2] = 0.1;
  m.linear_acceleration[2] = 9.81;
  kestrel::imu_t gyro_only = m;
  gyro_only.fields = kestrel::imu_t::HAS_GYRO;
  return {m, gyro_only};
}

// The planner's: the tree read back (OctoMap's reader, behind kestrel's structure check), then
// projected onto the flight band.
void convert_octomap(const kestrel::octomap_t& m) { planner::map_from_message(m, 0.2, 1.8); }
std::vector<kestrel::octomap_t> octomap_examples() {
  mapper::VoxelMap map;
  // A wall of occupied cells and free space in front of it, as a scan would leave them.
  for (double y = -0.5; y <= 0.5; y += 0.1) {
    for (double z = 0.3; z <= 1.5; z += 0.1) {
      mapper::Key k;
      if (map.keys().key(1.0, y, z, k)) map.update(k, map.hit());
      if (map.keys().key(0.5, y, z, k)) map.update(k, map.miss());
    }
  }
  std::vector<kestrel::octomap_t> out;
  for (auto format : {mapper::OctreeFormat::kBinary, mapper::OctreeFormat::kFull}) {
    kestrel::octomap_t m{};
    m.utime = 1000000;
    m.revision = 3;
    m.resolution = map.resolution();
    m.format = format == mapper::OctreeFormat::kBinary ? kestrel::octomap_t::FORMAT_BINARY : kestrel::octomap_t::FORMAT_FULL;
    m.data = mapper::encode_octree(map, format);
    m.size = static_cast<int32_t>(m.data.size());
    out.push_back(m);
  }
  return out;
}

void convert_plan_request(const kestrel::plan_request_t& m) { planner::query_from_message(m, 0.01); }
std::vector<kestrel::plan_request_t> plan_request_examples() {
  kestrel::plan_request_t r{};
  r.utime = 1000000;
  r.request_id = 4;
  r.start_mode = kestrel::plan_request_t::START_FROM_STATE;
  r.goal[0] = 3.0;
  r.goal[2] = 1.0;
  r.planner = kestrel::plan_request_t::PLANNER_BRM;
  r.objective = kestrel::plan_request_t::OBJECTIVE_MIN_GOAL_UNCERTAINTY;
  return {r};
}

// The path follower's.
void convert_plan(const kestrel::plan_t& m) {
  control::FollowerNode node{control::FollowerNodeOptions{}};
  node.on_plan(m);
}
std::vector<kestrel::plan_t> plan_examples() {
  kestrel::plan_t p{};
  p.utime = 1000000;
  p.request_id = 4;
  p.status = kestrel::plan_t::STATUS_OK;
  p.message = "ok";
  p.num_waypoints = 2;
  p.waypoints = {{0, 0, 1, 0}, {2, 0.5, 1, 0.2}};
  p.covariance_trace = {0.01, 0.05};
  p.length = 2.06;
  kestrel::plan_t none = p;
  none.status = kestrel::plan_t::STATUS_NO_PATH;
  none.num_waypoints = 0;
  none.waypoints.clear();
  none.covariance_trace.clear();
  return {p, none};
}

void convert_pose3(const kestrel::pose3_t& m) { transport::from_message(m, "POSE"); }
std::vector<kestrel::pose3_t> pose3_examples() { return {pose(1, 2, 3)}; }

void convert_pose(const kestrel::pose_t& m) {
  transport::from_message(m.pose, "POSE");
  transport::covariance_from(m.covariance);
}
std::vector<kestrel::pose_t> pose_examples() {
  kestrel::pose_t p{};
  p.utime = 1000000;
  p.parent_frame = "world";
  p.child_frame = "body";
  p.pose = pose(0.5, 0, 1);
  set_identity_covariance(p.covariance, 1e-4);
  return {p};
}

// The launcher's: a heartbeat on its board, then the table it prints, which must stay
// printable whatever bytes the message's strings hold.
void convert_status(const kestrel::process_status_t& m) {
  const auto now = std::chrono::steady_clock::now();
  launch::HealthBoard board;
  board.started(m.name, m.pid, now);
  board.heartbeat(m, now);
  const std::string table = board.table(now);
  for (const char c : table) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n') || u == 0x7f) defect("lcm-process_status_t", "a control byte reached the health table");
  }
}
std::vector<kestrel::process_status_t> status_examples() {
  kestrel::process_status_t s{};
  s.utime = 1700000000000000;
  s.name = "estimator";
  s.pid = 4242;
  s.state = kestrel::process_status_t::STATE_DEGRADED;
  s.message = "rejecting IMU: accelerometer beyond its range";
  s.num_subscriptions = 1;
  s.subscriptions = {"IMU"};
  s.num_publications = 1;
  s.publications = {"STATE"};
  s.messages_in = 100;
  s.messages_out = 99;
  s.messages_rejected = 1;
  return {s};
}

// The launcher's: the counts on its board, then the table it prints at the end.
void convert_rejections(const kestrel::rejection_counts_t& m) {
  const auto now = std::chrono::steady_clock::now();
  launch::HealthBoard board;
  board.started(m.name, m.pid, now);
  board.rejections(m);
  const std::string table = board.rejections_table();
  for (const char c : table) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n') || u == 0x7f) defect("lcm-rejection_counts_t", "a control byte reached the rejections table");
  }
}
std::vector<kestrel::rejection_counts_t> rejections_examples() {
  kestrel::rejection_counts_t r{};
  r.utime = 1700000000000000;
  r.name = "estimator";
  r.pid = 4242;
  r.rejected = 3;
  kestrel::rejection_reason_t a{};
  a.channel = "IMU";
  a.reason = "accelerometer # m/s^2 beyond the sensor's range of # m/s^2";
  a.count = 2;
  a.last = "accelerometer 500 m/s^2 beyond the sensor's range of 160 m/s^2";
  kestrel::rejection_reason_t b{};
  b.channel = "VO_UPDATE";
  b.reason = "reference keyframe # is unknown";
  b.count = 1;
  b.last = "reference keyframe 1700000000 is unknown";
  r.reasons = {a, b};
  r.num_reasons = 2;
  return {r, kestrel::rejection_counts_t{}};
}

std::vector<kestrel::rejection_reason_t> reason_examples() { return rejections_examples().front().reasons; }

std::vector<kestrel::replay_ack_t> ack_examples() {
  kestrel::replay_ack_t a{};
  a.session = 9;
  a.process = "vo";
  a.channel = "CAMERA_RGBD";
  a.input_utime = 1000000;
  a.num_outputs = 1;
  a.output_channels = {"VO_UPDATE"};
  return {a};
}

std::vector<kestrel::replay_control_t> control_examples() {
  kestrel::replay_control_t c{};
  c.session = 9;
  c.command = kestrel::replay_control_t::COMMAND_RESET;
  return {c};
}

// Every consumer of frames (vo, slam, rgbd-codec) decodes with decode_rgbd, whose result must
// keep RgbdFrame's invariants; the mapper with decode_rgbd_deferring_colour, which must accept
// what decode_rgbd accepts (its colour failing only where decode_rgbd does) and give the same
// frame.
void convert_frame(const kestrel::rgbd_frame_t& m) {
  std::optional<RgbdFrame> whole;
  try {
    whole = transport::decode_rgbd(m, "CAMERA_RGBD");
  } catch (const InputError&) {
  }
  if (whole) {
    try {
      whole->validate("CAMERA_RGBD");
    } catch (const InputError& e) {
      defect("rgbd-codec", std::string("a decoded frame breaks RgbdFrame's invariants: ") + e.what());
    }
  }
  transport::RgbdDeferredColour deferred;
  try {
    deferred = transport::decode_rgbd_deferring_colour(m, "CAMERA_RGBD");
    if (deferred.colour) deferred.frame.rgb = deferred.colour();
  } catch (const InputError&) {
    if (whole) defect("rgbd-codec", "the deferred decode rejects a frame decode_rgbd accepts");
    throw;
  }
  if (!whole) defect("rgbd-codec", "the deferred decode accepts a frame decode_rgbd rejects");
  auto same = [](const cv::Mat& a, const cv::Mat& b) {
    return a.empty() ? b.empty() : !b.empty() && a.size() == b.size() && cv::norm(a, b, cv::NORM_INF) == 0.0;
  };
  if (!same(deferred.frame.rgb, whole->rgb) || !same(deferred.frame.depth_mm, whole->depth_mm))
    defect("rgbd-codec", "the deferred decode gives another frame than decode_rgbd");
}
std::vector<kestrel::rgbd_frame_t> frame_examples() {
  RgbdFrame f;
  f.utime = f.depth_utime = 1000000;
  f.seq = 3;
  f.camera = small_camera(64, 48);
  f.sensor = sensor_model::kSimulator;
  f.rgb = cv::Mat(48, 64, CV_8UC3);
  f.depth_mm = cv::Mat(48, 64, CV_16UC1);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      f.rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uint8_t>(4 * u), static_cast<uint8_t>(5 * v), static_cast<uint8_t>((u * v) % 256));
      f.depth_mm.at<uint16_t>(v, u) = static_cast<uint16_t>(u % 9 == 0 ? 0 : 800 + 20 * u + 7 * v);
    }
  }
  using kestrel::rgbd_frame_t;
  std::vector<rgbd_frame_t> out;
  for (int8_t rgb : {rgbd_frame_t::RGB_RGB8, rgbd_frame_t::RGB_JPEG}) {
    for (int8_t depth : {rgbd_frame_t::DEPTH_U16_MM, rgbd_frame_t::DEPTH_U16_MM_ZSTD}) {
      transport::RgbdEncoding e;
      e.rgb = rgb;
      e.depth = depth;
      out.push_back(transport::encode_rgbd(f, e));
    }
  }
  RgbdFrame depth_only = f;
  depth_only.rgb = cv::Mat();
  transport::RgbdEncoding e;
  e.rgb = rgbd_frame_t::RGB_NONE;
  out.push_back(transport::encode_rgbd(depth_only, e));
  return out;
}

void convert_correction(const kestrel::slam_correction_t& m) { estimator::correction_from_message(m, "SLAM_CORRECTION"); }
std::vector<kestrel::slam_correction_t> correction_examples() {
  kestrel::slam_correction_t c{};
  c.utime = 1000000;
  c.keyframe_id = 1000000;
  c.graph_revision = 2;
  c.T_world_body = pose(1, 0, 1);
  set_identity_covariance(c.covariance, 1e-4);
  return {c};
}

std::vector<kestrel::slam_edge_t> edge_examples() {
  kestrel::slam_edge_t e{};
  e.from_id = 1;
  e.to_id = 2;
  e.kind = kestrel::slam_edge_t::KIND_LOOP_CLOSURE;
  e.T_from_to = pose(0.2, 0, 0, 0.05);
  return {e};
}

// The mapper's: each keyframe's poses as it takes them.
void convert_graph(const kestrel::slam_graph_t& m) {
  for (const auto& k : m.keyframes) mapper::to_graph_keyframe(k, "SLAM_GRAPH");
}
std::vector<kestrel::slam_graph_t> graph_examples() {
  kestrel::slam_graph_t g{};
  g.utime = 2000000;
  g.revision = 5;
  g.keyframes = {keyframe(1000000, 0.0), keyframe(2000000, 0.4)};
  g.num_keyframes = 2;
  g.edges = edge_examples();
  g.num_edges = 1;
  return {g};
}

void convert_keyframe(const kestrel::slam_keyframe_t& m) { mapper::to_graph_keyframe(m, "SLAM_GRAPH"); }
std::vector<kestrel::slam_keyframe_t> keyframe_examples() { return {keyframe(1000000, 0.3)}; }

// The vehicle's controller, the path follower and the planner take STATE; each refusal is
// its own (one consumer's refusal does not spare the others the message).
void convert_state(const kestrel::state_t& m) {
  sim::VehicleEstimate estimate;
  sim::vehicle_estimate(m, estimate);
  bool refused = false;
  try {
    control::FollowerNode node{control::FollowerNodeOptions{}};
    node.on_state(m);
  } catch (const InputError&) {
    refused = true;
  }
  planner::state_from_message(m);
  if (refused) throw InputError("STATE: refused by the path follower");
}
std::vector<kestrel::state_t> state_examples() {
  kestrel::state_t s{};
  s.utime = 1000000;
  s.seq = 12;
  s.filter = kestrel::state_t::FILTER_EKF;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body = pose(0.5, 0.2, 1.0);
  s.velocity[0] = 0.1;
  s.cov_dim = 3;
  s.covariance = {{1e-4, 0, 0}, {0, 1e-4, 0}, {0, 0, 1e-4}};
  return {s};
}

void convert_command(const kestrel::vehicle_command_t& m) { sim::vehicle_command(m); }
std::vector<kestrel::vehicle_command_t> command_examples() {
  kestrel::vehicle_command_t c{};
  c.utime = 1000000;
  c.mode = kestrel::vehicle_command_t::MODE_POSITION;
  c.position[0] = 1.0;
  c.position[2] = 1.0;
  c.yaw = 0.2;
  kestrel::vehicle_command_t hold = c;
  hold.mode = kestrel::vehicle_command_t::MODE_HOLD;
  return {c, hold};
}

// The estimator's and SLAM's.
void convert_vo(const kestrel::vo_update_t& m) {
  estimator::vo_from_message(m, "VO_UPDATE");
  slam::motion_from_message(m, "VO_UPDATE");
}
std::vector<kestrel::vo_update_t> vo_examples() {
  kestrel::vo_update_t u{};
  u.utime = 1033333;
  u.seq = 31;
  u.reference_utime = 1000000;
  u.previous_utime = 1000000;
  u.status = kestrel::vo_update_t::STATUS_OK;
  u.T_reference_current = pose(0.01, 0, 0, 0.002);
  set_identity_covariance(u.covariance, 1e-6);
  u.translation_floor = 1e-3;
  u.rotation_floor = 1e-3;
  u.T_body_camera = transport::to_message(Eigen::Isometry3d::Identity());
  u.num_features = 400;
  u.num_inliers = 120;
  kestrel::vo_update_t lost = u;
  lost.status = kestrel::vo_update_t::STATUS_INSUFFICIENT_INLIERS;
  return {u, lost};
}

// ---- LCM logs -----------------------------------------------------------------------------

// As `kestrel replay` and the eval tools read a log: every intact event, damage counted.
bool run_log(const uint8_t* data, size_t size) {
  return accepted([&] {
    transport::LogReader log(scratch_file("fuzz.lcmlog", data, size));
    int64_t bytes = 0;
    while (auto e = log.next()) bytes += static_cast<int64_t>(e->data.size() + e->channel.size());
    if (bytes > static_cast<int64_t>(size)) defect("lcm-log", "events hold more bytes than the file");
    log.damage_report();
  });
}
std::vector<Bytes> log_seeds() {
  const std::string path = scratch_dir() + "/seed.lcmlog";
  {
    transport::LogWriter log(path);
    log.write_message("IMU", 1000000, imu_examples()[0]);
    log.write_message("STATE", 1000100, state_examples()[0]);
    log.write_message("CAMERA_RGBD", 1033333, frame_examples()[1]);
    log.close();
  }
  return {file_bytes(path)};
}

}  // namespace

std::vector<Target> message_targets() {
  using namespace kestrel;
  return {
      {"lcm-camera_info_t", "a camera_info_t message", &run_message<camera_info_t, &convert_camera>,
       &encoded<camera_info_t, &camera_examples>},
      {"lcm-ground_truth_t", "GROUND_TRUTH, as the mapper and eval take it",
       &run_message<ground_truth_t, &convert_ground_truth>, &encoded<ground_truth_t, &ground_truth_examples>},
      {"lcm-imu_t", "IMU, as the estimator takes it", &run_message<imu_t, &convert_imu>, &encoded<imu_t, &imu_examples>},
      {"lcm-octomap_t", "MAP_OCTOMAP, as the planner reads and projects it",
       &run_message<octomap_t, &convert_octomap>, &encoded<octomap_t, &octomap_examples>},
      {"lcm-plan_request_t", "PLAN_REQUEST, as the planner takes it", &run_message<plan_request_t, &convert_plan_request>,
       &encoded<plan_request_t, &plan_request_examples>},
      {"lcm-plan_t", "PLAN, as the path follower takes it", &run_message<plan_t, &convert_plan>,
       &encoded<plan_t, &plan_examples>},
      {"lcm-pose3_t", "a pose3_t", &run_message<pose3_t, &convert_pose3>, &encoded<pose3_t, &pose3_examples>},
      {"lcm-pose_t", "a pose_t with covariance", &run_message<pose_t, &convert_pose>, &encoded<pose_t, &pose_examples>},
      {"lcm-process_status_t", "PROCESS_STATUS, as kestrel launch shows it",
       &run_message<process_status_t, &convert_status>, &encoded<process_status_t, &status_examples>},
      {"lcm-rejection_counts_t", "PROCESS_REJECTIONS, as kestrel launch shows it",
       &run_message<rejection_counts_t, &convert_rejections>, &encoded<rejection_counts_t, &rejections_examples>},
      {"lcm-rejection_reason_t", "a rejection_reason_t (decoded only)",
       &run_message<rejection_reason_t, &decode_only<rejection_reason_t>>, &encoded<rejection_reason_t, &reason_examples>},
      {"lcm-replay_ack_t", "REPLAY_ACK (decoded only)", &run_message<replay_ack_t, &decode_only<replay_ack_t>>,
       &encoded<replay_ack_t, &ack_examples>},
      {"lcm-replay_control_t", "REPLAY_CONTROL (decoded only)",
       &run_message<replay_control_t, &decode_only<replay_control_t>>, &encoded<replay_control_t, &control_examples>},
      {"rgbd-codec", "CAMERA_RGBD frames (raw, JPEG, zstd), as vo, slam and the mapper decode them",
       &run_message<rgbd_frame_t, &convert_frame>, &encoded<rgbd_frame_t, &frame_examples>},
      {"lcm-slam_correction_t", "SLAM_CORRECTION, as the estimator takes it",
       &run_message<slam_correction_t, &convert_correction>, &encoded<slam_correction_t, &correction_examples>},
      {"lcm-slam_edge_t", "a slam_edge_t (decoded only)", &run_message<slam_edge_t, &decode_only<slam_edge_t>>,
       &encoded<slam_edge_t, &edge_examples>},
      {"lcm-slam_graph_t", "SLAM_GRAPH, as the mapper takes it", &run_message<slam_graph_t, &convert_graph>,
       &encoded<slam_graph_t, &graph_examples>},
      {"lcm-slam_keyframe_t", "a SLAM keyframe, as the mapper takes it",
       &run_message<slam_keyframe_t, &convert_keyframe>, &encoded<slam_keyframe_t, &keyframe_examples>},
      {"lcm-state_t", "STATE, as the vehicle, the path follower and the planner take it", &run_message<state_t, &convert_state>,
       &encoded<state_t, &state_examples>},
      {"lcm-vehicle_command_t", "VEHICLE_COMMAND, as the simulated vehicle takes it",
       &run_message<vehicle_command_t, &convert_command>, &encoded<vehicle_command_t, &command_examples>},
      {"lcm-vo_update_t", "VO_UPDATE, as the estimator and SLAM take it", &run_message<vo_update_t, &convert_vo>,
       &encoded<vo_update_t, &vo_examples>},
      {"lcm-log", "an LCM log file, as replay and eval read it", &run_log, &log_seeds},
  };
}

}  // namespace kestrel::fuzz
