// ros/bag_import.h on small bags written with librosbag: pairing by the TUM reader's rule, the
// order of the messages, IMU samples, ground truth from tf and from PoseStamped, the camera,
// and the errors that name the topic.

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <typeinfo>

#include <console_bridge/console.h>
#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "ros/bag_import.h"
#include "ros/legacy_camera_info.h"
#include "ros/ros_convert.h"
#include "test/ros/bag_writer.h"
#include "test/support/test_support.h"

// A CameraInfo as ROS before Electric wrote it (TUM's 2011 bags may hold it), for the writer:
// the old MD5 and definition, the layout of ros/legacy_camera_info.h.
struct OldCameraInfoToWrite {
  kestrel::ros1::legacy::CameraInfo m;
};
constexpr const char* kOldCameraInfoDefinition =
    "# This message defines meta information for a camera.\n"
    "Header header\nuint32 height\nuint32 width\nRegionOfInterest roi\n"
    "float64[5]  D # The distortion parameters\nfloat64[9]  K\nfloat64[9]  R\nfloat64[12] P\n\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n\n"
    "================================================================================\n"
    "MSG: sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\n";
namespace ros {
namespace message_traits {
template <>
struct MD5Sum<OldCameraInfoToWrite> {
  static const char* value() { return "1b5cf7f984c229b6141ceb3a955aa18f"; }
  static const char* value(const OldCameraInfoToWrite&) { return value(); }
};
template <>
struct DataType<OldCameraInfoToWrite> {
  static const char* value() { return "sensor_msgs/CameraInfo"; }
  static const char* value(const OldCameraInfoToWrite&) { return value(); }
};
template <>
struct Definition<OldCameraInfoToWrite> {
  static const char* value() { return kOldCameraInfoDefinition; }
  static const char* value(const OldCameraInfoToWrite&) { return value(); }
};
}  // namespace message_traits
namespace serialization {
template <>
struct Serializer<OldCameraInfoToWrite> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T m) {
    stream.next(m.m);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};
}  // namespace serialization
}  // namespace ros

namespace kestrel {
namespace {

constexpr int kW = 4, kH = 3;

struct Written {
  std::vector<std::string> channels;
  std::vector<RgbdFrame> frames;
  std::vector<imu_t> imu;
  std::vector<ground_truth_t> truth;
};

Written import(const std::string& bag, const ros1::BagImportOptions& o, ros1::BagImportStats* stats = nullptr) {
  Written w;
  ros1::ImportSink sink;
  sink.publish = [&](const std::string& channel, int64_t, const std::vector<uint8_t>& bytes) {
    w.channels.push_back(channel);
    if (channel == channel::kCameraRgbd)
      w.frames.push_back(transport::decode_rgbd(transport::decode_message<rgbd_frame_t>(bytes.data(), bytes.size(), "c"), "c"));
    if (channel == channel::kImu) w.imu.push_back(transport::decode_message<imu_t>(bytes.data(), bytes.size(), "i"));
    if (channel == channel::kGroundTruth)
      w.truth.push_back(transport::decode_message<ground_truth_t>(bytes.data(), bytes.size(), "g"));
  };
  const ros1::BagImportStats s = ros1::import_bag(bag, o, sink);
  if (stats) *stats = s;
  return w;
}

void write_bag(const std::string& path, const std::function<void(rosbag::Bag&)>& fill) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  fill(bag);
  bag.close();
}

void put_colour(rosbag::Bag& bag, int64_t utime, const std::string& encoding = "rgb8") {
  bag.write("/camera/rgb/image_color", ros1::to_ros_time(utime), test::colour_image(utime, kW, kH, encoding));
  bag.write("/camera/rgb/camera_info", ros1::to_ros_time(utime), test::camera_info(utime, kW, kH, 5.0, 6.0));
}
void put_depth(rosbag::Bag& bag, int64_t utime, uint16_t mm) {
  bag.write("/camera/depth/image", ros1::to_ros_time(utime), test::depth_image_mm(utime, kW, kH, mm));
}

geometry_msgs::TransformStamped tf(int64_t utime, const std::string& parent, const std::string& child,
                                   const Eigen::Vector3d& t, double yaw) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = ros1::to_ros_time(utime);
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = t.x();
  m.transform.translation.y = t.y();
  m.transform.translation.z = t.z();
  m.transform.rotation.z = std::sin(yaw / 2);
  m.transform.rotation.w = std::cos(yaw / 2);
  return m;
}

TEST(BagImport, PairsByTheTumRuleAndCountsWhatIsLeftOver) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  // Colour at 1.000, 1.033, 1.066, 1.200 s; depth at 1.010, 1.050, 1.500 s. By the rule (the
  // nearest depth within 20 ms, a depth image may serve two): 1.000-1.010, 1.033-1.050
  // (17 ms; 1.010 is 23 ms away), 1.066-1.050 (16 ms, shared); 1.200 has none (150 ms);
  // 1.500 serves nothing.
  write_bag(bag, [](rosbag::Bag& b) {
    for (int64_t t : {1000000, 1033000, 1066000, 1200000}) put_colour(b, t);
    put_depth(b, 1010000, 1000);
    put_depth(b, 1050000, 2000);
    put_depth(b, 1500000, 3000);
  });
  ros1::BagImportStats s;
  const Written w = import(bag, {}, &s);
  EXPECT_EQ(s.colour_images, 4u);
  EXPECT_EQ(s.depth_images, 3u);
  EXPECT_EQ(s.frames, 3u);
  EXPECT_EQ(s.unmatched_colour, 1u);
  EXPECT_EQ(s.unused_depth, 1u);
  EXPECT_EQ(s.shared_depth, 1u);
  ASSERT_EQ(w.frames.size(), 3u);
  const int64_t colour_of[3] = {1000000, 1033000, 1066000};
  const int64_t depth_of[3] = {1010000, 1050000, 1050000};
  const uint16_t mm_of[3] = {1000, 2000, 2000};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(w.frames[i].utime, colour_of[i]);
    EXPECT_EQ(w.frames[i].depth_utime, depth_of[i]);
    EXPECT_EQ(w.frames[i].seq, static_cast<int64_t>(i));
    EXPECT_EQ(w.frames[i].depth_mm.at<uint16_t>(2, 3), mm_of[i]);
    EXPECT_EQ(w.frames[i].rgb.at<cv::Vec3b>(2, 3), cv::Vec3b(23, 102, 203));
    EXPECT_EQ(w.frames[i].sensor, "kinect1");
    EXPECT_EQ(w.frames[i].camera.fx, 5.0);
    EXPECT_EQ(w.frames[i].camera.fy, 6.0);
    EXPECT_EQ(w.frames[i].camera.cx, 1.5);
    EXPECT_TRUE(w.frames[i].T_body_camera.isApprox(Eigen::Isometry3d::Identity()));
  }
  EXPECT_EQ(s.ground_truth, "none: no /tf topic");
}

TEST(BagImport, FramesFollowTheHeaderStampsNotTheBagOrderAndARepeatedStampIsDroppedOnce) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  // Received (bag time) in the order 1.066, 1.000, 1.033, 1.000 again (another picture), the
  // depth images likewise late and out of order.
  write_bag(bag, [](rosbag::Bag& b) {
    int64_t received = 2000000;
    for (const auto& [stamp, mm] : {std::pair{1066000, 3000}, std::pair{1000000, 1000}, std::pair{1033000, 2000},
                                    std::pair{1000000, 4000}}) {
      sensor_msgs::Image colour = test::colour_image(stamp, kW, kH);
      colour.data[0] = static_cast<uint8_t>(mm / 1000);  // tells the two 1.000 pictures apart
      b.write("/camera/rgb/image_color", ros1::to_ros_time(received), colour);
      b.write("/camera/rgb/camera_info", ros1::to_ros_time(received), test::camera_info(stamp, kW, kH, 5, 5));
      b.write("/camera/depth/image", ros1::to_ros_time(received + 1), test::depth_image_mm(stamp + 1000, kW, kH, mm));
      received += 10000;
    }
  });
  ros1::BagImportStats s;
  const Written w = import(bag, {}, &s);
  EXPECT_EQ(s.repeated_stamps, 2u);  // one colour, one depth
  EXPECT_EQ(s.colour_images, 3u);
  ASSERT_EQ(w.frames.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(w.frames[i].utime, 1000000 + static_cast<int64_t>(i) * 33000) << i;
    EXPECT_EQ(w.frames[i].seq, static_cast<int64_t>(i));
  }
  // The first image received with a repeated stamp is the one kept, colour and depth.
  EXPECT_EQ(w.frames[0].rgb.at<cv::Vec3b>(0, 0)[0], 1);
  EXPECT_EQ(w.frames[0].depth_mm.at<uint16_t>(0, 0), 1000);
  EXPECT_EQ(w.frames[2].depth_mm.at<uint16_t>(0, 0), 3000);
}

TEST(BagImport, ImuAndGroundTruthComeBeforeAFrameOfTheSameTime) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    put_colour(b, 2000000);
    put_depth(b, 2000000, 500);
    const sensor_msgs::Imu imu = test::accel_sample(2000000, {0.0, 9.81, 0.0});
    b.write("/imu", imu.header.stamp, imu);
    const sensor_msgs::Imu later = test::accel_sample(2005000, {0.0, 9.80, 0.1});
    b.write("/imu", later.header.stamp, later);
    sensor_msgs::Imu nothing = test::accel_sample(2006000, {0.0, 0.0, 0.0});
    nothing.linear_acceleration_covariance[0] = -1.0;  // measures nothing: skipped, counted
    b.write("/imu", nothing.header.stamp, nothing);
    geometry_msgs::PoseStamped p;
    p.header.stamp = ros1::to_ros_time(2000000);
    p.pose.position.x = 0.5;
    p.pose.orientation.w = 1.0;
    b.write("/mocap/pose", p.header.stamp, p);
  });
  ros1::BagImportOptions o;
  o.pose_topic = "/mocap/pose";
  ros1::BagImportStats s;
  const Written w = import(bag, o, &s);
  EXPECT_EQ(w.channels, (std::vector<std::string>{"IMU", "GROUND_TRUTH", "CAMERA_RGBD", "IMU"}));
  ASSERT_EQ(w.imu.size(), 2u);
  EXPECT_EQ(s.imu_empty, 1u);
  EXPECT_EQ(w.imu[1].utime, 2005000);
  EXPECT_EQ(w.imu[1].seq, 1);
  EXPECT_EQ(w.imu[1].fields, imu_t::HAS_ACCEL);
  EXPECT_EQ(w.imu[1].linear_acceleration[1], 9.80);
  EXPECT_EQ(w.imu[1].linear_acceleration[2], 0.1);
  ASSERT_EQ(w.truth.size(), 1u);
  EXPECT_EQ(w.truth[0].frame, ground_truth_t::FRAME_CAMERA);
  EXPECT_EQ(w.truth[0].T_world_frame.position[0], 0.5);
}

TEST(BagImport, GroundTruthComposesTheTfChainAtTheMocapsStamps) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    put_colour(b, 3000000);
    put_depth(b, 3000000, 500);
    // The body at (1, 0, 0) turned 90 degrees left, then at (2, 0, 0) unturned; the camera
    // 1 m along the body's y, its mount published only after the first mocap pose (a mount is
    // rigid: the first value serves before it) and from a frame of another tree (ignored).
    for (const auto& [t, x, yaw] : {std::tuple{3000000, 1.0, M_PI / 2}, std::tuple{3010000, 2.0, 0.0}}) {
      tf2_msgs::TFMessage m;
      m.transforms.push_back(tf(t, "/world", "/body", {x, 0, 0}, yaw));
      if (t == 3010000) {
        m.transforms.push_back(tf(t, "/body", "/cam", {0, 1, 0}, 0.0));
        m.transforms.push_back(tf(t, "/elsewhere", "/cam", {9, 9, 9}, 0.0));
      }
      b.write("/tf", ros1::to_ros_time(t), m);
    }
  });
  ros1::BagImportOptions o;
  o.camera_frame = "cam";
  ros1::BagImportStats s;
  const Written w = import(bag, o, &s);
  EXPECT_EQ(s.ground_truth, "/tf: world -> body -> cam");
  ASSERT_EQ(w.truth.size(), 2u);
  // (1, 0, 0) + Rz(90)(0, 1, 0) = (0, 0, 0); then (2, 0, 0) + (0, 1, 0) = (2, 1, 0).
  const Eigen::Isometry3d T0 = transport::from_message(w.truth[0].T_world_frame, "gt");
  const Eigen::Isometry3d T1 = transport::from_message(w.truth[1].T_world_frame, "gt");
  EXPECT_TRUE(T0.translation().isZero(1e-12)) << T0.translation().transpose();
  EXPECT_TRUE(T1.translation().isApprox(Eigen::Vector3d(2, 1, 0), 1e-12)) << T1.translation().transpose();
  EXPECT_NEAR(Eigen::AngleAxisd(T0.linear()).angle(), M_PI / 2, 1e-12);

  // Frames that the tree does not join: no ground truth, and the summary says why.
  o.camera_frame = "openni_rgb_optical_frame";
  import(bag, o, &s);
  EXPECT_EQ(s.ground_truth_poses, 0u);
  EXPECT_NE(s.ground_truth.find("no chain of transforms from 'world' to 'openni_rgb_optical_frame'"), std::string::npos)
      << s.ground_truth;
}

TEST(BagImport, ImuIsTurnedIntoTheCamerasAxesByTheTfMount) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    sensor_msgs::Image colour = test::colour_image(1000, kW, kH);
    colour.header.frame_id = "camera_color_optical_frame";
    b.write("/camera/rgb/image_color", ros1::to_ros_time(1000), colour);
    b.write("/camera/rgb/camera_info", ros1::to_ros_time(1000), test::camera_info(1000, kW, kH, 5, 5));
    put_depth(b, 1000, 500);
    sensor_msgs::Imu imu = test::accel_sample(1000, {1.0, 0.0, 0.0});
    imu.header.frame_id = "camera_imu_optical_frame";
    imu.angular_velocity_covariance[0] = 0.0;
    imu.angular_velocity.z = 0.5;
    b.write("/imu", ros1::to_ros_time(1000), imu);
    // Both frames hang from camera_link (as a RealSense driver's /tf_static): the camera's
    // optical frame is camera_link turned 90 degrees about z, the IMU's frame is camera_link.
    tf2_msgs::TFMessage mounts;
    mounts.transforms.push_back(tf(0, "camera_link", "camera_color_optical_frame", {0.01, 0, 0}, M_PI / 2));
    mounts.transforms.push_back(tf(0, "camera_link", "camera_imu_optical_frame", {0, 0.02, 0}, 0.0));
    b.write("/tf_static", ros1::to_ros_time(1), mounts);
  });
  ros1::BagImportStats s;
  const Written w = import(bag, {}, &s);
  EXPECT_EQ(s.imu_axes, "rotated from 'camera_imu_optical_frame' to 'camera_color_optical_frame' by /tf");
  ASSERT_EQ(w.imu.size(), 1u);
  // The IMU's x axis is the camera's -y (the camera is turned +90 degrees about the shared z).
  EXPECT_NEAR(w.imu[0].linear_acceleration[0], 0.0, 1e-15);
  EXPECT_NEAR(w.imu[0].linear_acceleration[1], -1.0, 1e-15);
  EXPECT_NEAR(w.imu[0].angular_velocity[2], 0.5, 1e-15);
  EXPECT_EQ(w.imu[0].fields, imu_t::HAS_ACCEL | imu_t::HAS_GYRO);

  // Without the tf topic the frames are not joined: as published, and the summary says why.
  ros1::BagImportOptions o;
  o.tf_topic = "/no_tf";
  const Written raw = import(bag, o, &s);
  EXPECT_EQ(raw.imu[0].linear_acceleration[0], 1.0);
  EXPECT_EQ(s.imu_axes,
            "as published: 'camera_imu_optical_frame' is not joined to the images' 'camera_color_optical_frame' on "
            "tf (no tf topic)");
}

TEST(BagImport, IntrinsicsReplaceAMissingCameraInfo) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    b.write("/camera/rgb/image_color", ros1::to_ros_time(1), test::colour_image(1, kW, kH, "bgr8"));
    put_depth(b, 1, 500);
  });
  std::string e = test::input_error_of([&] { import(bag, {}); });
  EXPECT_NE(e.find("/camera/rgb/camera_info: no such topic"), std::string::npos) << e;
  ros1::BagImportOptions o;
  o.intrinsics = PinholeCamera::vga(7, 8, 1, 1);
  const Written w = import(bag, o);
  ASSERT_EQ(w.frames.size(), 1u);
  EXPECT_EQ(w.frames[0].camera.width, kW);
  EXPECT_EQ(w.frames[0].camera.fx, 7.0);
  EXPECT_EQ(w.frames[0].rgb.at<cv::Vec3b>(2, 3), cv::Vec3b(23, 102, 203));  // bgr8 read as such
}

TEST(BagImport, ReadsTheCameraInfoOfRosBeforeElectric) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    b.write("/camera/rgb/image_color", ros1::to_ros_time(1), test::colour_image(1, kW, kH));
    put_depth(b, 1, 500);
    OldCameraInfoToWrite info;
    info.m.header.stamp = ros1::to_ros_time(1);
    info.m.width = kW;
    info.m.height = kH;
    info.m.K = {525.0, 0, 1.5, 0, 520.0, 1.0, 0, 0, 1};
    info.m.D = {0.25, -0.5, 0.001, 0.002, 0.75};
    b.write("/camera/rgb/camera_info", ros1::to_ros_time(1), info);
  });
  ros1::BagImportStats s;
  const Written w = import(bag, {}, &s);
  ASSERT_EQ(w.frames.size(), 1u);
  EXPECT_EQ(s.camera_infos, 1u);
  EXPECT_EQ(w.frames[0].camera.fx, 525.0);
  EXPECT_EQ(w.frames[0].camera.fy, 520.0);
  EXPECT_EQ(w.frames[0].camera.cx, 1.5);
  EXPECT_EQ(w.frames[0].camera.cy, 1.0);
  EXPECT_EQ(w.frames[0].camera.distortion, (std::array<double, 5>{0.25, -0.5, 0.001, 0.002, 0.75}));
}

TEST(BagImport, OnlyTheExactOldCameraInfoDefinitionIsReadTheOldWay) {
  const std::string old = kOldCameraInfoDefinition;
  EXPECT_TRUE(ros1::legacy::is_pre_electric_camera_info(old));
  // Absolute type names and a constant change nothing.
  std::string absolute = old;
  absolute.replace(absolute.find("Header header"), 13, "std_msgs/Header header\nuint8 SOME_CONSTANT=3");
  EXPECT_TRUE(ros1::legacy::is_pre_electric_camera_info(absolute));
  // Today's message, a field more or of another size, or a changed RegionOfInterest: no.
  EXPECT_FALSE(ros1::legacy::is_pre_electric_camera_info(ros::message_traits::Definition<sensor_msgs::CameraInfo>::value()));
  std::string more = old;
  more.replace(more.find("float64[12] P"), 13, "float64[12] P\nuint32 binning_x");
  EXPECT_FALSE(ros1::legacy::is_pre_electric_camera_info(more));
  std::string sized = old;
  sized.replace(sized.find("float64[5]"), 10, "float64[]");
  EXPECT_FALSE(ros1::legacy::is_pre_electric_camera_info(sized));
  std::string roi = old;
  roi.replace(roi.find("uint32 width\n", roi.find("MSG: sensor_msgs")), 13, "uint32 width\nbool do_rectify\n");
  EXPECT_FALSE(ros1::legacy::is_pre_electric_camera_info(roi));
}

TEST(BagImport, StoppingEndsTheImportEarlyAndSaysSo) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    for (int64_t t : {1000000, 1033000, 1066000}) {
      put_colour(b, t);
      put_depth(b, t, 1000);
    }
  });
  int published = 0;
  ros1::ImportSink sink;
  sink.publish = [&](const std::string&, int64_t, const std::vector<uint8_t>&) { ++published; };
  sink.stopping = [&] { return published >= 1; };  // Ctrl-C once the first frame is out
  const ros1::BagImportStats s = ros1::import_bag(bag, {}, sink);
  EXPECT_TRUE(s.stopped);
  EXPECT_EQ(published, 1);
  EXPECT_EQ(s.frames, 1u);
}

// As fuzz_corpus_test does for kestrel's own decoders: a small bag cut at 30 lengths and with
// single bytes flipped at 150 places either imports or ends in InputError; no other exception,
// and (in the sanitizer build) no memory error in librosbag or in the conversions. librosbag
// is outside kestrel, so this is a check of what it does, not a fuzz target of ours.
TEST(BagImport, CutAndFlippedBagsEndInInputErrorOrAnImport) {
  test::TempDir dir;
  const std::string bag = (dir / "seed.bag").string();
  write_bag(bag, [](rosbag::Bag& b) {
    for (int64_t t : {1000000, 1033000}) {
      put_colour(b, t);
      put_depth(b, t + 2000, 700);
      b.write("/imu", ros1::to_ros_time(t), test::accel_sample(t, {0, 9.8, 0}));
      tf2_msgs::TFMessage m;
      m.transforms.push_back(tf(t, "world", "openni_rgb_optical_frame", {0.1, 0, 0}, 0.2));
      b.write("/tf", ros1::to_ros_time(t), m);
    }
  });
  const std::string seed = test::read_file(bag);
  ASSERT_GT(seed.size(), 1000u);
  ros1::ImportSink sink;
  sink.publish = [](const std::string&, int64_t, const std::vector<uint8_t>&) {};
  size_t imported = 0, refused = 0;
  auto attempt = [&](const std::string& bytes, const std::string& what) {
    const std::string path = (dir / "m.bag").string();
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    try {
      ros1::import_bag(path, {}, sink);
      ++imported;
    } catch (const InputError&) {
      ++refused;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": " << typeid(e).name() << ": " << e.what();
    }
  };
  // librosbag's complaints on its console would bury the test's output (the tool silences them).
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  for (size_t k = 0; k < 30; ++k) attempt(seed.substr(0, seed.size() * k / 30), "cut at " + std::to_string(k) + "/30");
  const unsigned char values[3] = {0x00, 0x80, 0xff};
  for (size_t k = 0; k < 150; ++k) {
    std::string flipped = seed;
    const size_t at = (k * 7919) % seed.size();  // spread over the whole file
    flipped[at] = static_cast<char>(values[k % 3]);
    attempt(flipped, "byte " + std::to_string(at) + " set to " + std::to_string(values[k % 3]));
  }
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
  std::cout << imported << " imported, " << refused << " refused\n";
  EXPECT_GT(refused, 30u);  // the cuts, and flips in headers and the index
  EXPECT_GT(imported, 0u);  // flips in pixels change pixels
}

TEST(BagImport, BadBagsAreErrorsNamingTheTopic) {
  test::TempDir dir;
  const std::string bag = (dir / "a.bag").string();
  auto error_of = [&](const std::function<void(rosbag::Bag&)>& fill) {
    write_bag(bag, fill);
    return test::input_error_of([&] { import(bag, {}); });
  };
  std::string e = error_of([](rosbag::Bag& b) { put_colour(b, 1); });
  EXPECT_NE(e.find("/camera/depth/image: no such topic"), std::string::npos) << e;
  e = error_of([](rosbag::Bag& b) {
    put_colour(b, 1);
    b.write("/camera/depth/image", ros1::to_ros_time(1), test::accel_sample(1, {0, 0, 9.8}));
  });
  EXPECT_NE(e.find("/camera/depth/image: messages are sensor_msgs/Imu"), std::string::npos) << e;
  e = error_of([](rosbag::Bag& b) {
    b.write("/camera/rgb/image_color", ros1::to_ros_time(1), test::colour_image(1, kW, kH));
    put_depth(b, 1, 500);
    b.write("/camera/rgb/camera_info", ros1::to_ros_time(1), test::camera_info(1, kW + 1, kH, 5, 5));
  });
  EXPECT_NE(e.find("/camera/rgb/camera_info: CameraInfo is 5x3, the images on /camera/rgb/image_color 4x3"),
            std::string::npos) << e;
  e = error_of([](rosbag::Bag& b) {
    put_colour(b, 1);
    put_depth(b, 1000000, 500);  // 1 s later: nothing pairs
  });
  EXPECT_NE(e.find("no image on /camera/rgb/image_color has one on /camera/depth/image within 0.02"), std::string::npos) << e;
  EXPECT_NE(test::input_error_of([&] { import((dir / "absent.bag").string(), {}); }).find("absent.bag"), std::string::npos);
}

}  // namespace
}  // namespace kestrel
