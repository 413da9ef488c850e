// ros-bridge's way in (ros/camera_stream.h) on hand-made messages: the frames it publishes as
// messages arrive are bag-import's of the same messages in a bag, byte for byte (same pairing
// rule, same conversions), whatever the interleaving of the topics; and what it refuses.

#include <gtest/gtest.h>

#include <map>

#include <rosbag/bag.h>

#include "common/error.h"
#include "common/transport/channels.h"
#include "ros/bag_import.h"
#include "ros/camera_stream.h"
#include "common/transport/message.h"
#include "kestrel/imu_t.hpp"
#include "ros/tf_tree.h"
#include "test/ros/bag_writer.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

constexpr int64_t kStreamT0 = 1305031102000000;
constexpr int kStreamW = 4, kStreamH = 3;

struct Published {
  std::string channel;
  int64_t utime = 0;
  std::vector<uint8_t> bytes;
  bool operator==(const Published& o) const { return channel == o.channel && utime == o.utime && bytes == o.bytes; }
};

// Colour at 30 Hz, but the last 20 ms after the one before; depth near each, but none within
// 20 ms of the third colour image (no frame), and the last depth image (206 ms) nearest to both
// the last two colour images (shared; and the last colour image has no depth image after it:
// decided by flush()).
struct Stream {
  std::vector<sensor_msgs::Image> colour, depth;
  std::vector<sensor_msgs::CameraInfo> info;
  std::vector<sensor_msgs::Imu> imu;
};

Stream hand_made_stream() {
  Stream s;
  const int64_t colour_us[] = {0, 33333, 66667, 100000, 133333, 166667, 200000, 220000};
  const int64_t depth_us[] = {5000, 29000, 104000 /* colour 66667 has none within 20 ms */, 138000, 171000, 206000};
  for (const int64_t t : colour_us) {
    sensor_msgs::Image c = test::colour_image(kStreamT0 + t, kStreamW, kStreamH, "bgr8");
    c.data[0] = static_cast<uint8_t>(t / 1000);  // distinct images
    s.colour.push_back(c);
    s.info.push_back(test::camera_info(kStreamT0 + t, kStreamW, kStreamH, 500, 501));
  }
  for (const int64_t t : depth_us) s.depth.push_back(test::depth_image_mm(kStreamT0 + t, kStreamW, kStreamH, static_cast<uint16_t>(1000 + t / 1000)));
  for (int i = 0; i < 20; ++i) s.imu.push_back(test::accel_sample(kStreamT0 + i * 12000, Eigen::Vector3d(0.1 * i, 9.8, -0.2)));
  return s;
}

std::vector<Published> imported(const Stream& s, const std::filesystem::path& bag_path) {
  {
    rosbag::Bag bag(bag_path.string(), rosbag::bagmode::Write);
    for (size_t i = 0; i < s.colour.size(); ++i) {
      bag.write("/camera/rgb/image_color", s.colour[i].header.stamp, s.colour[i]);
      bag.write("/camera/rgb/camera_info", s.info[i].header.stamp, s.info[i]);
    }
    for (const auto& d : s.depth) bag.write("/camera/depth/image", d.header.stamp, d);
    for (const auto& m : s.imu) bag.write("/imu", m.header.stamp, m);
  }
  std::vector<Published> out;
  ros1::ImportSink sink;
  sink.publish = [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); };
  ros1::import_bag(bag_path.string(), ros1::BagImportOptions{}, sink);
  return out;
}

std::vector<Published> only(const std::vector<Published>& all, const std::string& channel) {
  std::vector<Published> out;
  for (const auto& p : all)
    if (p.channel == channel) out.push_back(p);
  return out;
}

// Feeds the stream with depth `lag` images behind colour, and the CameraInfo after `info_after`
// colour images; then flushes (the camera went quiet).
std::vector<Published> streamed(const Stream& s, size_t lag, size_t info_after, ros1::CameraStreamStats* stats = nullptr) {
  std::vector<Published> out;
  ros1::CameraStream stream(ros1::CameraTopicOptions{}, "ros-bridge",
                            [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); });
  size_t d = 0;
  for (size_t i = 0; i < s.colour.size(); ++i) {
    stream.colour(s.colour[i]);
    if (i + 1 == info_after) stream.camera_info(s.info[i]);
    for (; d < s.depth.size() && d + lag <= i; ++d) stream.depth(s.depth[d]);
  }
  if (info_after > s.colour.size()) stream.camera_info(s.info.back());
  for (; d < s.depth.size(); ++d) stream.depth(s.depth[d]);
  for (const auto& m : s.imu) stream.imu(m);
  stream.flush();
  if (stats) *stats = stream.stats();
  return out;
}

TEST(CameraStream, FramesAreBagImportsByteForByteWhateverTheTopicsInterleaving) {
  test::TempDir dir;
  const Stream s = hand_made_stream();
  const auto want = imported(s, dir / "s.bag");
  const auto want_frames = only(want, channel::kCameraRgbd);
  // 8 colour images: one has no depth image within 20 ms; one depth image serves two.
  ASSERT_EQ(want_frames.size(), 7u);
  for (const size_t lag : {0u, 1u, 3u})
    for (const size_t info_after : {1u, 4u}) {
      ros1::CameraStreamStats stats;
      const auto got = streamed(s, lag, info_after, &stats);
      EXPECT_TRUE(only(got, channel::kCameraRgbd) == want_frames) << "lag " << lag << ", CameraInfo after " << info_after;
      EXPECT_TRUE(only(got, channel::kImu) == only(want, channel::kImu));
      EXPECT_EQ(stats.frames, 7u);
      EXPECT_EQ(stats.unmatched_colour, 1u);
      EXPECT_EQ(stats.camera_infos, 1u);
    }
}

// The hand-made stream with its colour images in a RealSense's optical frame and the IMU in
// the IMU's; both hang from camera_link (the camera turned 90 degrees about z), as a driver's
// /tf_static says.
Stream mounted_stream() {
  Stream s = hand_made_stream();
  for (auto& c : s.colour) c.header.frame_id = "camera_color_optical_frame";
  for (auto& m : s.imu) m.header.frame_id = "camera_imu_optical_frame";
  return s;
}
tf2_msgs::TFMessage realsense_mounts() {
  Eigen::Isometry3d optical = Eigen::Isometry3d::Identity(), imu = Eigen::Isometry3d::Identity();
  optical.translation() = Eigen::Vector3d(0.01, 0, 0);
  optical.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  imu.translation() = Eigen::Vector3d(0, 0.02, 0);
  tf2_msgs::TFMessage m;
  m.transforms.push_back(test::transform(0, "camera_link", "camera_color_optical_frame", optical));
  m.transforms.push_back(test::transform(0, "camera_link", "camera_imu_optical_frame", imu));
  return m;
}

TEST(CameraStream, ImuSamplesTakeTheImagesAxesByTheTreesMountAsBagImportTurnsThem) {
  const Stream s = mounted_stream();
  test::TempDir dir;
  {
    rosbag::Bag bag((dir / "a.bag").string(), rosbag::bagmode::Write);
    for (size_t i = 0; i < s.colour.size(); ++i) {
      bag.write("/camera/rgb/image_color", s.colour[i].header.stamp, s.colour[i]);
      bag.write("/camera/rgb/camera_info", s.info[i].header.stamp, s.info[i]);
    }
    for (const auto& d : s.depth) bag.write("/camera/depth/image", d.header.stamp, d);
    for (const auto& m : s.imu) bag.write("/imu", m.header.stamp, m);
    bag.write("/tf_static", ros::Time(1), realsense_mounts());
  }
  std::vector<Published> want;
  ros1::ImportSink sink;
  sink.publish = [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { want.push_back({c, u, b}); };
  ros1::BagImportStats imported;
  imported = ros1::import_bag((dir / "a.bag").string(), ros1::BagImportOptions{}, sink);
  ASSERT_EQ(imported.imu_axes, "rotated from 'camera_imu_optical_frame' to 'camera_color_optical_frame' by /tf");

  // Live: the mounts come first (latched), the IMU before any colour image waits for the
  // images' frame, and goes out rotated with the first colour image.
  ros1::TfTree tree;
  tree.add(realsense_mounts(), "test: /tf_static");
  std::vector<Published> out;
  ros1::CameraStream stream(
      ros1::CameraTopicOptions{}, "ros-bridge",
      [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); }, &tree, "/tf");
  for (size_t i = 0; i < 5; ++i) stream.imu(s.imu[i]);
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(stream.waiting());
  stream.camera_info(s.info[0]);
  stream.colour(s.colour[0]);
  EXPECT_EQ(only(out, channel::kImu).size(), 5u);
  for (size_t i = 5; i < s.imu.size(); ++i) stream.imu(s.imu[i]);
  EXPECT_EQ(stream.stats().imu_axes, imported.imu_axes);
  EXPECT_TRUE(only(out, channel::kImu) == only(want, channel::kImu)) << "the IMU samples are bag-import's, byte for byte";
}

TEST(CameraStream, ImuSamplesTheTreeDoesNotJoinToTheImagesGoOutAsPublishedAfterASecond) {
  Stream s = mounted_stream();
  for (size_t i = 0; i < s.imu.size(); ++i) s.imu[i].header.stamp = ros1::to_ros_time(kStreamT0 + 100'000 * static_cast<int64_t>(i));
  ros1::TfTree tree;  // no mounts
  std::vector<Published> out;
  ros1::CameraStream stream(
      ros1::CameraTopicOptions{}, "ros-bridge",
      [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); }, &tree, "/tf");
  stream.colour(s.colour[0]);
  for (size_t i = 0; i < 10; ++i) stream.imu(s.imu[i]);  // 0.9 s of IMU time: the mount may come yet
  EXPECT_TRUE(out.empty());
  stream.imu(s.imu[10]);  // 1 s
  const auto imu = only(out, channel::kImu);
  ASSERT_EQ(imu.size(), 11u);
  const auto first = transport::decode_message<imu_t>(imu[0].bytes.data(), imu[0].bytes.size(), "IMU");
  EXPECT_EQ(first.linear_acceleration[1], 9.8) << "as published";
  EXPECT_EQ(stream.stats().imu_axes,
            "as published: 'camera_imu_optical_frame' is not joined to the images' 'camera_color_optical_frame' on /tf");
  // A 1 kHz IMU: 400 samples wait at most (0.4 s), then go out as published.
  ros1::CameraStream fast(ros1::CameraTopicOptions{}, "ros-bridge",
                          [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); },
                          &tree, "/tf");
  fast.colour(s.colour[0]);
  for (int i = 0; i < 399; ++i) {
    sensor_msgs::Imu m = s.imu[0];
    m.header.stamp = ros1::to_ros_time(kStreamT0 + 1000 * i);
    fast.imu(m);
  }
  EXPECT_EQ(fast.stats().imu_samples, 0u);
  sensor_msgs::Imu last = s.imu[0];
  last.header.stamp = ros1::to_ros_time(kStreamT0 + 399'000);
  fast.imu(last);
  EXPECT_EQ(fast.stats().imu_samples, 400u);
  // A camera gone quiet releases what waits; without a tree, nothing waits.
  ros1::CameraStream no_tree(ros1::CameraTopicOptions{}, "ros-bridge",
                             [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); });
  no_tree.imu(s.imu[0]);
  EXPECT_FALSE(no_tree.waiting());
  EXPECT_EQ(no_tree.stats().imu_axes, "as published ('camera_imu_optical_frame'; no tf read)");
  ros1::CameraStream quiet(ros1::CameraTopicOptions{}, "ros-bridge",
                           [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); },
                           &tree, "/tf");
  quiet.imu(s.imu[0]);
  EXPECT_TRUE(quiet.waiting());
  quiet.flush();
  EXPECT_FALSE(quiet.waiting());
  EXPECT_EQ(quiet.stats().imu_samples, 1u);
}

TEST(CameraStream, AColourImageWaitsForADepthImageAfterIt) {
  const Stream s = hand_made_stream();
  std::vector<Published> out;
  ros1::CameraStream stream(ros1::CameraTopicOptions{}, "ros-bridge",
                            [&](const std::string& c, int64_t u, const std::vector<uint8_t>& b) { out.push_back({c, u, b}); });
  stream.camera_info(s.info[0]);
  stream.colour(s.colour[1]);  // 33.3 ms
  stream.depth(s.depth[1]);    // 29 ms: before it, a nearer one may come
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(stream.waiting());
  stream.depth(s.depth[2]);  // 104 ms: after it, so 29 ms is its nearest
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].utime, kStreamT0 + 33333);
  EXPECT_FALSE(stream.waiting());
}

TEST(CameraStream, ImagesNotAfterTheLastOfTheirTopicAreDroppedAndCounted) {
  const Stream s = hand_made_stream();
  size_t frames = 0;
  ros1::CameraStream stream(ros1::CameraTopicOptions{}, "ros-bridge",
                            [&](const std::string& c, int64_t, const std::vector<uint8_t>&) { frames += c == channel::kCameraRgbd; });
  stream.camera_info(s.info[0]);
  stream.colour(s.colour[1]);
  stream.colour(s.colour[0]);  // older
  stream.colour(s.colour[1]);  // repeated
  stream.depth(s.depth[1]);
  stream.depth(s.depth[0]);  // older
  stream.flush();
  EXPECT_EQ(stream.stats().out_of_order, 3u);
  EXPECT_EQ(frames, 1u);
}

TEST(CameraStream, AStreamThatCanGiveNoFrameIsAStreamErrorNamingTheTopic) {
  const Stream s = hand_made_stream();
  auto refusal = [&](const std::function<void(ros1::CameraStream&)>& feed) {
    ros1::CameraStream stream(ros1::CameraTopicOptions{}, "ros-bridge", [](const std::string&, int64_t, const std::vector<uint8_t>&) {});
    try {
      feed(stream);
    } catch (const ros1::StreamError& e) {
      return std::string(e.what());
    }
    return std::string("(no StreamError)");
  };
  sensor_msgs::Image depth = s.depth[0];
  depth.encoding = "8UC1";
  EXPECT_NE(refusal([&](auto& st) { st.depth(depth); }).find("ros-bridge: /camera/depth/image at 1305031102.005000 s: depth encoding '8UC1' is not one kestrel reads"),
            std::string::npos);
  sensor_msgs::CameraInfo info = s.info[0];
  info.K[0] = 0;
  EXPECT_NE(refusal([&](auto& st) { st.camera_info(info); }).find("/camera/rgb/camera_info at 1305031102.000000 s: CameraInfo focal length fx=0"),
            std::string::npos);
  // A CameraInfo of another size than the images.
  EXPECT_NE(refusal([&](auto& st) {
              st.colour(s.colour[0]);
              st.camera_info(test::camera_info(kStreamT0, 8, 6, 500, 500));
            }).find("/camera/rgb/camera_info: CameraInfo is 8x6, the images on /camera/rgb/image_color 4x3"),
            std::string::npos);
  // Depth not registered to colour (another size).
  EXPECT_NE(refusal([&](auto& st) {
              st.colour(s.colour[0]);
              st.depth(test::depth_image_mm(kStreamT0, 8, 6, 1000));
            }).find("depth images are 8x6, the colour images on /camera/rgb/image_color 4x3"),
            std::string::npos);
}

TEST(CameraStream, OneBadMessageIsAnInputErrorAndTheStreamGoesOn) {
  const Stream s = hand_made_stream();
  size_t frames = 0;
  ros1::CameraStream stream(ros1::CameraTopicOptions{}, "ros-bridge",
                            [&](const std::string& c, int64_t, const std::vector<uint8_t>&) { frames += c == channel::kCameraRgbd; });
  stream.camera_info(s.info[0]);
  sensor_msgs::Image cut = s.colour[0];
  cut.data.resize(5);
  const std::string why = test::input_error_of([&] { stream.colour(cut); });
  EXPECT_NE(why.find("/camera/rgb/image_color at 1305031102.000000 s: 5 bytes of pixels, 36 expected"), std::string::npos) << why;
  sensor_msgs::Imu bad = s.imu[0];
  bad.linear_acceleration.x = std::nan("");
  EXPECT_NE(test::input_error_of([&] { stream.imu(bad); }).find("/imu at"), std::string::npos);
  stream.colour(s.colour[0]);
  stream.depth(s.depth[0]);
  EXPECT_EQ(frames, 1u);
  EXPECT_EQ(stream.stats().colour_images, 1u);
}

}  // namespace
}  // namespace kestrel
