// ros/bag_export.h: STATE as nav_msgs/Odometry (pose, twist and both covariances on a case
// worked by hand), and a log of hand-made messages exported and read back with librosbag.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <tuple>
#include <type_traits>

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Path.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "common/transport/rgbd_codec.h"
#include "ros/bag_export.h"
#include "ros/bag_import.h"
#include "ros/ros_convert.h"
#include "test/ros/bag_export_logs.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;
using test::make_state;

double cov(const boost::array<double, 36>& c, int r, int k) { return c[static_cast<size_t>(r * 6 + k)]; }

TEST(BagExport, OdometryPoseAndTwistAreStatesInRosFrames) {
  // Yaw 90 degrees: the body's x is the world's y.
  const Eigen::Isometry3d T = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  kestrel::state_t s = make_state(1500000, T, {1, 0, 0}, {0.1, 0.2, 0.3});
  s.seq = 7;
  const nav_msgs::Odometry o = ros1::odometry_from_state(s, "map", "base_link", "test");
  EXPECT_EQ(o.header.frame_id, "map");
  EXPECT_EQ(o.child_frame_id, "base_link");
  EXPECT_EQ(o.header.stamp, ros::Time(1, 500000000));
  EXPECT_EQ(o.header.seq, 7u);
  EXPECT_NEAR(o.pose.pose.position.x, 1, 1e-12);
  EXPECT_NEAR(o.pose.pose.position.y, 2, 1e-12);
  EXPECT_NEAR(o.pose.pose.position.z, 3, 1e-12);
  EXPECT_NEAR(o.pose.pose.orientation.w, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(o.pose.pose.orientation.z, std::sqrt(0.5), 1e-12);
  // v_world = (1, 0, 0) is the body's -y.
  EXPECT_NEAR(o.twist.twist.linear.x, 0, 1e-12);
  EXPECT_NEAR(o.twist.twist.linear.y, -1, 1e-12);
  EXPECT_NEAR(o.twist.twist.linear.z, 0, 1e-12);
  EXPECT_EQ(o.twist.twist.angular.x, 0.1);
  EXPECT_EQ(o.twist.twist.angular.z, 0.3);
}

// By hand, R = Rz(90 deg), v_world = (1, 0, 0) so v_body = (0, -1, 0), and diagonal blocks
// P_pp = diag(1, 2, 3), P_vv = diag(d, e, f) = (4, 5, 6), P_thth = diag(a, b, c) = (7, 8, 9) (body),
// P_bg = diag(10, 11, 12), P_ba = diag(13, 14, 15), plus P(dp_x, dtheta_x) = 0.5:
//  pose:  position diag(1, 2, 3); rotation R diag(7, 8, 9) R^T = diag(8, 7, 9); the cross term
//         dp_x with dtheta_x (body x = world y) lands at (x, rot y) = 0.5;
//  twist: linear R^T P_vv R + [v_b]x P_thth [v_b]x^T = diag(e, d, f) + diag(c, 0, a)
//         = diag(14, 4, 13); angular = P_bg = diag(10, 11, 12); no linear-angular term.
TEST(BagExport, CovariancesMappedFromTheErrorStateOnAHandWorkedCase) {
  const Eigen::Isometry3d T(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  kestrel::state_t s = make_state(1000000, T, {1, 0, 0}, {0, 0, 0});
  for (int i = 0; i < 15; ++i) s.covariance[i][i] = i + 1;
  s.covariance[0][6] = s.covariance[6][0] = 0.5;
  const nav_msgs::Odometry o = ros1::odometry_from_state(s, "map", "base_link", "test");
  const double pose_diag[6] = {1, 2, 3, 8, 7, 9};
  const double twist_diag[6] = {14, 4, 13, 10, 11, 12};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      double want_pose = r == c ? pose_diag[r] : 0.0;
      if ((r == 0 && c == 4) || (r == 4 && c == 0)) want_pose = 0.5;
      EXPECT_NEAR(cov(o.pose.covariance, r, c), want_pose, 1e-12) << "pose (" << r << ", " << c << ")";
      EXPECT_NEAR(cov(o.twist.covariance, r, c), r == c ? twist_diag[r] : 0.0, 1e-12) << "twist (" << r << ", " << c << ")";
    }
  // Visual-only: the angular velocity's covariance is not in the state (zero: unknown).
  s.filter = kestrel::state_t::FILTER_VISUAL_ONLY;
  const nav_msgs::Odometry v = ros1::odometry_from_state(s, "map", "base_link", "test");
  for (int r = 3; r < 6; ++r) EXPECT_EQ(cov(v.twist.covariance, r, r), 0.0);
  EXPECT_NEAR(cov(v.twist.covariance, 0, 0), 14, 1e-12);
  // Another cov_dim: both covariances unknown (zero).
  s.cov_dim = 0;
  s.covariance.clear();
  const nav_msgs::Odometry none = ros1::odometry_from_state(s, "map", "base_link", "test");
  for (double x : none.pose.covariance) EXPECT_EQ(x, 0.0);
  for (double x : none.twist.covariance) EXPECT_EQ(x, 0.0);
}

TEST(BagExport, ANonFinitePoseIsAnInputError) {
  kestrel::state_t s = make_state(1000000, Eigen::Isometry3d::Identity(), {0, 0, 0}, {0, 0, 0});
  s.T_world_body.position[1] = std::nan("");
  EXPECT_THROW(ros1::odometry_from_state(s, "map", "base_link", "test"), InputError);
}

TEST(BagExport, EveryStateIsAnOdometryAndATransformAndTheCameraMountIsStatic) {
  test::TempDir dir;
  const fs::path log = dir / "in.lcmlog";
  const auto states = test::write_state_log(log, 20, /*with_camera=*/true);
  {
    rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
    const ros1::BagExportStats s = ros1::export_log(log.string(), {}, bag);
    EXPECT_EQ(s.messages.at("/kestrel/odom"), 20);
    EXPECT_EQ(s.messages.at("/tf"), 20);
    EXPECT_EQ(s.messages.at("/tf_static"), 1);
  }
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Read);
  size_t i = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/odom"))) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(o);
    ASSERT_LT(i, states.size());
    const kestrel::state_t& s = states[i++];
    EXPECT_EQ(m.getTime(), ros1::to_ros_time(s.utime));
    EXPECT_EQ(o->header.stamp, m.getTime());
    EXPECT_NEAR(o->pose.pose.position.x, s.T_world_body.position[0], 1e-9);
    EXPECT_NEAR(o->pose.pose.position.y, s.T_world_body.position[1], 1e-9);
    EXPECT_NEAR(o->pose.pose.position.z, s.T_world_body.position[2], 1e-9);
    EXPECT_NEAR(o->pose.pose.orientation.w, s.T_world_body.orientation[0], 1e-9);
    EXPECT_NEAR(o->pose.pose.orientation.x, s.T_world_body.orientation[1], 1e-9);
    EXPECT_NEAR(o->pose.pose.orientation.y, s.T_world_body.orientation[2], 1e-9);
    EXPECT_NEAR(o->pose.pose.orientation.z, s.T_world_body.orientation[3], 1e-9);
  }
  EXPECT_EQ(i, states.size());
  size_t tf = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf"))) {
    const auto t = m.instantiate<tf2_msgs::TFMessage>();
    ASSERT_TRUE(t);
    ASSERT_EQ(t->transforms.size(), 1u);
    EXPECT_EQ(t->transforms[0].header.frame_id, "map");
    EXPECT_EQ(t->transforms[0].child_frame_id, "base_link");
    EXPECT_NEAR(t->transforms[0].transform.translation.x, states[tf].T_world_body.position[0], 1e-9);
    ++tf;
  }
  EXPECT_EQ(tf, states.size());
  size_t fixed = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf_static"))) {
    const auto t = m.instantiate<tf2_msgs::TFMessage>();
    ASSERT_TRUE(t);
    ASSERT_EQ(t->transforms.size(), 1u);
    EXPECT_EQ(t->transforms[0].header.frame_id, "base_link");
    EXPECT_EQ(t->transforms[0].child_frame_id, "camera");
    // test::kBodyCamera: the camera 10 cm ahead, looking along the body's x (optical z forward).
    EXPECT_NEAR(t->transforms[0].transform.translation.x, 0.1, 1e-12);
    const Eigen::Quaterniond q(t->transforms[0].transform.rotation.w, t->transforms[0].transform.rotation.x,
                               t->transforms[0].transform.rotation.y, t->transforms[0].transform.rotation.z);
    EXPECT_NEAR((q * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);
    ++fixed;
  }
  EXPECT_EQ(fixed, 1u);
}

TEST(BagExport, FrameNamesAreOptions) {
  test::TempDir dir;
  test::write_state_log(dir / "in.lcmlog", 2, true);
  ros1::BagExportOptions o;
  o.world_frame = "odom";
  o.body_frame = "body";
  o.camera_frame = "rgb_optical";
  {
    rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
    ros1::export_log((dir / "in.lcmlog").string(), o, bag);
  }
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto odom = m.instantiate<nav_msgs::Odometry>()) {
      EXPECT_EQ(odom->header.frame_id, "odom");
      EXPECT_EQ(odom->child_frame_id, "body");
    } else if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      const auto& t = tf->transforms.at(0);
      EXPECT_TRUE((t.header.frame_id == "odom" && t.child_frame_id == "body") ||
                  (t.header.frame_id == "body" && t.child_frame_id == "rgb_optical"))
          << t.header.frame_id << " -> " << t.child_frame_id;
    }
  }
}

kestrel::vo_update_t vo_update(int64_t utime, int64_t reference_utime, int8_t status, const Eigen::Isometry3d& T) {
  kestrel::vo_update_t m{};
  m.utime = utime;
  m.seq = utime / 100000;
  m.reference_utime = reference_utime;
  m.status = status;
  m.T_reference_current = transport::to_message(T);
  m.T_body_camera = transport::to_message(Eigen::Isometry3d::Identity());
  return m;
}

// The VO's chain by eval's rules, worked by hand: frame 1 is the first (identity), 2 and 3
// are against keyframe 1, 4 fails (no pose), 5 is against keyframe 3, 6 against frame 4 (which
// has no pose: chained on from the last pose, 5's).
TEST(BagExport, VoUpdatesAreChainedAsEvalChainsThemAndTruthPassesThrough) {
  test::TempDir dir;
  const Eigen::Isometry3d A = Eigen::Translation3d(0.1, 0, 0) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d B = Eigen::Translation3d(0, 0.2, 0.05) * Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX());
  const Eigen::Isometry3d C = Eigen::Translation3d(0.3, 0, 0.1) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  using V = kestrel::vo_update_t;
  {
    transport::LogWriter w((dir / "vo.lcmlog").string());
    w.write_message(channel::kVoUpdate, 100000, vo_update(100000, 0, V::STATUS_NO_REFERENCE, Eigen::Isometry3d::Identity()));
    w.write_message(channel::kVoUpdate, 200000, vo_update(200000, 100000, V::STATUS_OK, A));
    w.write_message(channel::kVoUpdate, 300000, vo_update(300000, 100000, V::STATUS_OK, B));
    w.write_message(channel::kVoUpdate, 400000, vo_update(400000, 300000, V::STATUS_INSUFFICIENT_MATCHES, A));
    w.write_message(channel::kVoUpdate, 500000, vo_update(500000, 300000, V::STATUS_OK, C));
    w.write_message(channel::kVoUpdate, 500000, vo_update(500000, 300000, V::STATUS_OK, C));  // repeated: skipped
    w.write_message(channel::kVoUpdate, 600000, vo_update(600000, 400000, V::STATUS_OK, A));
    kestrel::ground_truth_t g{};
    g.utime = 250000;
    g.frame = kestrel::ground_truth_t::FRAME_CAMERA;
    g.T_world_frame = transport::to_message(C);
    w.write_message(channel::kGroundTruth, g.utime, g);
    w.close();
  }
  ros1::BagExportStats stats;
  {
    rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
    stats = ros1::export_log((dir / "vo.lcmlog").string(), {}, bag);
  }
  EXPECT_EQ(stats.messages.at("/kestrel/vo"), 5);
  EXPECT_EQ(stats.messages.at("/kestrel/ground_truth"), 1);
  EXPECT_EQ(stats.messages.at("/tf_static"), 1);  // the mounting from the first VO_UPDATE
  EXPECT_EQ(stats.vo_without_estimate, 1);
  EXPECT_EQ(stats.vo_out_of_order, 1);
  EXPECT_EQ(stats.truth_of, "camera");
  const std::vector<std::pair<int64_t, Eigen::Isometry3d>> want = {
      {100000, Eigen::Isometry3d::Identity()}, {200000, A}, {300000, B}, {500000, B * C}, {600000, B * C * A}};
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Read);
  size_t i = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/vo"))) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(o);
    ASSERT_LT(i, want.size());
    EXPECT_EQ(o->header.stamp, ros1::to_ros_time(want[i].first));
    EXPECT_EQ(o->header.frame_id, "vo");
    EXPECT_EQ(o->child_frame_id, "camera");
    const Eigen::Isometry3d& T = want[i].second;
    const Eigen::Quaterniond q(o->pose.pose.orientation.w, o->pose.pose.orientation.x, o->pose.pose.orientation.y,
                               o->pose.pose.orientation.z);
    EXPECT_NEAR((Eigen::Vector3d(o->pose.pose.position.x, o->pose.pose.position.y, o->pose.pose.position.z) -
                 T.translation()).norm(), 0, 1e-9) << i;
    EXPECT_NEAR(Eigen::AngleAxisd(q.toRotationMatrix().transpose() * T.linear()).angle(), 0, 1e-9) << i;
    ++i;
  }
  EXPECT_EQ(i, want.size());
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/ground_truth"))) {
    const auto p = m.instantiate<geometry_msgs::PoseStamped>();
    ASSERT_TRUE(p);
    EXPECT_EQ(p->header.frame_id, "map");
    EXPECT_EQ(p->header.stamp, ros1::to_ros_time(250000));
    EXPECT_NEAR(p->pose.position.x, 0.3, 1e-12);
    EXPECT_NEAR(p->pose.position.z, 0.1, 1e-12);
    EXPECT_NEAR(p->pose.orientation.z, std::sin(0.15), 1e-12);
  }
}

// Every SLAM_GRAPH revision is a Path of its keyframes in time order and a LINE_LIST of its loop
// closures; a PLAN is a Path of its
// waypoints (yaw as a turn about z), an unsuccessful one an empty Path.
TEST(BagExport, GraphsAndPlansArePaths) {
  test::TempDir dir;
  {
    transport::LogWriter w((dir / "paths.lcmlog").string());
    for (int revision = 1; revision <= 3; ++revision) {
      kestrel::slam_graph_t g{};
      g.revision = revision;
      for (int k = revision; k >= 1; --k) {  // newest first: the Path puts them in time order
        kestrel::slam_keyframe_t kf{};
        kf.id = k;
        kf.utime = 1000000 * k;
        kf.T_world_camera = transport::to_message(Eigen::Isometry3d(Eigen::Translation3d(k + 0.01 * revision, 0, 0)));
        kf.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
        g.keyframes.push_back(kf);
      }
      g.num_keyframes = static_cast<int32_t>(g.keyframes.size());
      // Revision 3 closes a loop from keyframe 3 to 1, and has one to a keyframe it lacks (9).
      if (revision == 3) {
        for (const auto& [from, to, kind] : {std::tuple{3, 1, kestrel::slam_edge_t::KIND_LOOP_CLOSURE},
                                            std::tuple{2, 3, kestrel::slam_edge_t::KIND_ODOMETRY},
                                            std::tuple{9, 1, kestrel::slam_edge_t::KIND_LOOP_CLOSURE}}) {
          kestrel::slam_edge_t e{};
          e.from_id = from;
          e.to_id = to;
          e.kind = kind;
          e.T_from_to = transport::to_message(Eigen::Isometry3d::Identity());
          g.edges.push_back(e);
        }
        g.num_edges = static_cast<int32_t>(g.edges.size());
      }
      g.utime = 1000000 * revision;
      w.write_message(channel::kSlamGraph, g.utime, g);
    }
    kestrel::plan_t plan{};
    plan.utime = 3500000;
    plan.request_id = 9;
    plan.status = kestrel::plan_t::STATUS_OK;
    plan.waypoints = {{0, 0, 1, 0}, {1, 2, 1.5, M_PI / 2}};
    plan.covariance_trace = {0.1, 0.2};
    plan.num_waypoints = 2;
    w.write_message(channel::kPlan, plan.utime, plan);
    kestrel::plan_t none{};
    none.utime = 3600000;
    none.status = kestrel::plan_t::STATUS_NO_PATH;
    w.write_message(channel::kPlan, none.utime, none);
    w.close();
  }
  {
    rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
    const ros1::BagExportStats s = ros1::export_log((dir / "paths.lcmlog").string(), {}, bag);
    EXPECT_EQ(s.messages.at("/kestrel/slam/keyframes"), 3);
    EXPECT_EQ(s.messages.at("/kestrel/plan"), 2);
  }
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Read);
  int revision = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/slam/keyframes"))) {
    const auto p = m.instantiate<nav_msgs::Path>();
    ASSERT_TRUE(p);
    ++revision;
    EXPECT_EQ(p->header.frame_id, "map");
    EXPECT_EQ(p->header.stamp, ros1::to_ros_time(1000000 * revision));
    ASSERT_EQ(p->poses.size(), static_cast<size_t>(revision));
    for (int k = 1; k <= revision; ++k) {
      EXPECT_EQ(p->poses[k - 1].header.stamp, ros1::to_ros_time(1000000 * k));
      EXPECT_NEAR(p->poses[k - 1].pose.position.x, k + 0.01 * revision, 1e-12);
    }
  }
  EXPECT_EQ(revision, 3);
  // Loops: none in revisions 1 and 2 (DELETEALL), then the segment from keyframe 3 to 1.
  std::vector<visualization_msgs::MarkerArray> loops;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/slam/loops")))
    loops.push_back(*m.instantiate<visualization_msgs::MarkerArray>());
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(loops[0].markers.at(0).action, visualization_msgs::Marker::DELETEALL);
  const visualization_msgs::Marker& loop = loops[2].markers.at(0);
  EXPECT_EQ(loop.action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(loop.type, visualization_msgs::Marker::LINE_LIST);
  EXPECT_EQ(loop.header.frame_id, "map");
  ASSERT_EQ(loop.points.size(), 2u);
  EXPECT_NEAR(loop.points[0].x, 3.03, 1e-12);
  EXPECT_NEAR(loop.points[1].x, 1.03, 1e-12);
  std::vector<nav_msgs::Path> plans;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/plan")))
    plans.push_back(*m.instantiate<nav_msgs::Path>());
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_EQ(plans[0].poses.size(), 2u);
  EXPECT_EQ(plans[0].poses[1].pose.position.y, 2);
  EXPECT_EQ(plans[0].poses[1].pose.position.z, 1.5);
  EXPECT_NEAR(plans[0].poses[1].pose.orientation.z, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(plans[0].poses[1].pose.orientation.w, std::sqrt(0.5), 1e-12);
  EXPECT_TRUE(plans[1].poses.empty());
}

// With `images`, every CAMERA_RGBD is a colour and a depth Image and a CameraInfo; imported back
// by bag-import from those topics, each frame is the one written (pixels, stamps, camera).
TEST(BagExport, ImagesImportBackAsTheSameFrames) {
  test::TempDir dir;
  test::write_state_log(dir / "in.lcmlog", 30, true);
  ros1::BagExportOptions o;
  o.images = true;
  {
    rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
    const ros1::BagExportStats s = ros1::export_log((dir / "in.lcmlog").string(), o, bag);
    EXPECT_EQ(s.messages.at("/kestrel/camera/rgb/image_raw"), 10);
    EXPECT_EQ(s.messages.at("/kestrel/camera/depth/image_raw"), 10);
    EXPECT_EQ(s.messages.at("/kestrel/camera/rgb/camera_info"), 10);
  }
  std::vector<RgbdFrame> written;
  {
    transport::LogReader log((dir / "in.lcmlog").string());
    while (auto e = log.next())
      if (e->channel == channel::kCameraRgbd)
        written.push_back(transport::decode_rgbd(
            transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), "test"), "test"));
  }
  ros1::BagImportOptions io;
  io.colour_topic = "/kestrel/camera/rgb/image_raw";
  io.depth_topic = "/kestrel/camera/depth/image_raw";
  io.camera_info_topic = "/kestrel/camera/rgb/camera_info";
  io.imu_topic = "";
  io.tf_topic = "";
  io.sensor = "";
  std::vector<RgbdFrame> read;
  ros1::ImportSink sink;
  sink.publish = [&](const std::string& channel, int64_t, const std::vector<uint8_t>& bytes) {
    if (channel == channel::kCameraRgbd)
      read.push_back(transport::decode_rgbd(
          transport::decode_message<kestrel::rgbd_frame_t>(bytes.data(), bytes.size(), "test"), "test"));
  };
  ros1::import_bag((dir / "out.bag").string(), io, sink);
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].utime, written[i].utime);
    EXPECT_EQ(read[i].depth_utime, written[i].depth_utime);
    EXPECT_EQ(cv::norm(read[i].rgb, written[i].rgb, cv::NORM_INF), 0) << i;
    EXPECT_EQ(cv::norm(read[i].depth_mm, written[i].depth_mm, cv::NORM_INF), 0) << i;
    EXPECT_EQ(read[i].camera.fx, written[i].camera.fx);
    EXPECT_EQ(read[i].camera.cy, written[i].camera.cy);
    EXPECT_EQ(read[i].camera.distortion, written[i].camera.distortion);
  }
}

// A log cut at 30 lengths or with a byte flipped at 150 places (states, VO, truth, frames with
// --images) either exports or ends in InputError: nothing else escapes, nothing crashes.
TEST(BagExport, CutAndFlippedLogsEndInInputErrorOrAnExport) {
  test::TempDir dir;
  test::write_state_log(dir / "whole.lcmlog", 12, true);
  const std::string whole = test::read_file(dir / "whole.lcmlog");
  ros1::BagExportOptions o;
  o.images = true;
  int exported = 0, refused = 0;
  const auto attempt = [&](const std::string& bytes, const std::string& label) {
    std::ofstream(dir / "bad.lcmlog", std::ios::binary | std::ios::trunc) << bytes;
    rosbag::Bag bag((dir / "bad.bag").string(), rosbag::bagmode::Write);
    try {
      ros1::export_log((dir / "bad.lcmlog").string(), o, bag);
      ++exported;
    } catch (const InputError&) {
      ++refused;
    } catch (const std::exception& e) {
      ADD_FAILURE() << label << ": " << e.what();
    }
  };
  for (int i = 1; i <= 30; ++i) attempt(whole.substr(0, whole.size() * i / 31), "cut " + std::to_string(i));
  for (int i = 0; i < 150; ++i) {
    std::string bytes = whole;
    const size_t at = (bytes.size() * static_cast<size_t>(i)) / 150 + static_cast<size_t>(i % 7);
    bytes[at % bytes.size()] = static_cast<char>(bytes[at % bytes.size()] ^ (1 << (i % 8)));
    attempt(bytes, "flip " + std::to_string(i));
  }
  EXPECT_GT(refused, 30);  // every cut log at least
  std::cout << exported << " exported, " << refused << " refused\n";
}

TEST(BagExport, ALogWithoutTheChannelsIsAnInputError) {
  test::TempDir dir;
  {
    transport::LogWriter w((dir / "imu.lcmlog").string());
    kestrel::rgbd_frame_t f{};
    f.utime = 1000000;
    f.camera.T_body_camera = transport::to_message(Eigen::Isometry3d::Identity());
    w.write_message(channel::kCameraRgbd, f.utime, f);
    w.close();
  }
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
  try {
    ros1::export_log((dir / "imu.lcmlog").string(), {}, bag);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none of the channels exported"), std::string::npos) << e.what();
  }
}

// The channels are there but nothing in them can be exported (every VO_UPDATE failed): a bag of
// the camera's mounting alone would read as a result, so it is an InputError.
TEST(BagExport, ALogWhoseMessagesGiveNothingIsAnInputError) {
  test::TempDir dir;
  using V = kestrel::vo_update_t;
  {
    transport::LogWriter w((dir / "failed.lcmlog").string());
    w.write_message(channel::kVoUpdate, 200000, vo_update(200000, 100000, V::STATUS_INSUFFICIENT_MATCHES, Eigen::Isometry3d::Identity()));
    w.write_message(channel::kVoUpdate, 300000, vo_update(300000, 100000, V::STATUS_INSUFFICIENT_MATCHES, Eigen::Isometry3d::Identity()));
    w.close();
  }
  rosbag::Bag bag((dir / "out.bag").string(), rosbag::bagmode::Write);
  try {
    const auto stats = ros1::export_log((dir / "failed.lcmlog").string(), {}, bag);
    FAIL() << "no InputError; " << stats.total() << " messages written";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nothing exportable"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kestrel

namespace kestrel {
namespace {

// The Exporter forgets the VO's chain on reset() (the bridge's lock-step RESET): the VO's first
// frame after it starts a new chain at the identity instead of being dropped as out of order,
// and the camera's mount is sent again.
TEST(Exporter, ResetStartsANewVoChain) {
  std::map<std::string, int> written;
  std::vector<double> vo_x;
  ros1::RosSinkOf sink([&](const std::string& topic, const ros::Time&, const auto& m, bool) {
    ++written[topic];
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, nav_msgs::Odometry>) vo_x.push_back(m.pose.pose.position.x);
  });
  ros1::ExportStats stats;
  ros1::Exporter exporter({}, sink, stats);
  auto update = [](int64_t utime, int64_t reference, int8_t status, double x) {
    kestrel::vo_update_t m{};
    m.utime = utime;
    m.reference_utime = reference;
    m.status = status;
    m.T_reference_current = transport::to_message(Eigen::Isometry3d(Eigen::Translation3d(x, 0, 0)));
    m.T_body_camera = transport::to_message(Eigen::Isometry3d::Identity());
    return m;
  };
  exporter.vo(update(1000000, 0, kestrel::vo_update_t::STATUS_NO_REFERENCE, 0), "VO_UPDATE");
  exporter.vo(update(2000000, 1000000, kestrel::vo_update_t::STATUS_OK, 0.5), "VO_UPDATE");
  exporter.vo(update(1000000, 0, kestrel::vo_update_t::STATUS_NO_REFERENCE, 0), "VO_UPDATE");  // old: dropped
  EXPECT_EQ(stats.vo_out_of_order, 1);
  exporter.reset();
  exporter.vo(update(1000000, 0, kestrel::vo_update_t::STATUS_NO_REFERENCE, 0), "VO_UPDATE");
  exporter.vo(update(2000000, 1000000, kestrel::vo_update_t::STATUS_OK, 0.25), "VO_UPDATE");
  EXPECT_EQ(stats.vo_out_of_order, 1);
  EXPECT_EQ(vo_x, (std::vector<double>{0, 0.5, 0, 0.25}));
  EXPECT_EQ(written["/tf_static"], 2);
}

}  // namespace
}  // namespace kestrel
