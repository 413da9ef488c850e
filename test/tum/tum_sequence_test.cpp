// TumSequence on folders written by the test (test/tum/tum_fixture.h).

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <functional>


#include "common/error.h"
#include "common/numbers.h"
#include "common/image/image_io.h"
#include "common/time.h"
#include "drivers/tum/tum_sequence.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel::tum {
namespace {

using test::TumFixture;

// The error message of `f()`, which must throw InputError.
template <class F>
std::string input_error(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(TumSequence, FramesHoldTheImagesTimesAndIndices) {
  test::TempDir dir;
  const TumFixture fx(dir.path());
  const TumSequence s(fx.folder().string());
  ASSERT_EQ(s.size(), 5u);
  EXPECT_EQ(s.association().frames, 5u);
  EXPECT_EQ(s.association().unmatched_rgb, 0u);
  EXPECT_EQ(s.association().unused_depth, 0u);
  for (size_t k : {size_t{0}, size_t{4}}) {
    const int ki = static_cast<int>(k);
    const RgbdFrame f = s.frame(k);
    EXPECT_EQ(f.utime, TumFixture::rgb_utime(ki));
    EXPECT_EQ(f.depth_utime, TumFixture::depth_utime(ki));
    EXPECT_EQ(f.seq, ki);
    EXPECT_TRUE(f.T_body_camera.isApprox(Eigen::Isometry3d::Identity()));
    ASSERT_EQ(f.rgb.type(), CV_8UC3);
    ASSERT_EQ(f.depth_mm.type(), CV_16UC1);
    EXPECT_NO_THROW(f.validate("frame"));
    for (const auto& [row, col] : {std::pair{0, 0}, {479, 639}, {123, 456}, {0, 3}}) {
      EXPECT_EQ(f.rgb.at<cv::Vec3b>(row, col), TumFixture::rgb_at(ki, row, col)) << row << "," << col;
      // 1/5000 m -> mm, rounded: raw / 5.
      const int raw = TumFixture::depth_raw_at(ki, row, col);
      EXPECT_EQ(f.depth_mm.at<uint16_t>(row, col), (raw + 2) / 5) << row << "," << col;
    }
  }
}

TEST(TumSequence, DepthIsRoundedAndScaled) {
  const DepthToMillimetres plain;
  EXPECT_EQ(plain(uint16_t{0}), 0);
  EXPECT_EQ(plain(uint16_t{5000}), 1000);
  EXPECT_EQ(plain(uint16_t{5002}), 1000);  // 1000.4
  EXPECT_EQ(plain(uint16_t{5003}), 1001);  // 1000.6
  EXPECT_EQ(plain(uint16_t{65535}), 13107);
  EXPECT_EQ(plain(uint16_t{2}), 0);        // 0.4 mm: below anything a Kinect measures
  const DepthToMillimetres scaled(1.035);
  EXPECT_EQ(scaled(uint16_t{5000}), 1035);
  EXPECT_EQ(scaled(uint16_t{10000}), 2070);
  EXPECT_EQ(DepthToMillimetres(20.0)(uint16_t{65535}), 65535);  // saturates
  EXPECT_THROW(DepthToMillimetres(0.0), std::invalid_argument);
  EXPECT_THROW(DepthToMillimetres(std::nan("")), std::invalid_argument);

  test::TempDir dir;
  const TumFixture fx(dir.path(), 1);
  SequenceOptions o;
  o.depth_scale_correction = 1.035;
  const RgbdFrame f = TumSequence(fx.folder().string(), o).frame(0);
  EXPECT_EQ(f.depth_mm.at<uint16_t>(10, 10), scaled(TumFixture::depth_raw_at(0, 10, 10)));
}

TEST(TumSequence, IntrinsicsAndSensorModelFollowTheFolderNameOrTheOverride) {
  test::TempDir dir;
  struct Case {
    const char* name;
    TumCamera camera;
    double fx, fy, cx, cy;
  };
  for (const Case& c : {Case{"rgbd_dataset_freiburg1_xyz", TumCamera::kFreiburg1, 517.3, 516.5, 318.6, 255.3},
                        Case{"rgbd_dataset_freiburg2_desk", TumCamera::kFreiburg2, 520.9, 521.0, 325.1, 249.7},
                        Case{"rgbd_dataset_freiburg3_office", TumCamera::kFreiburg3, 535.4, 539.2, 320.1, 247.6},
                        Case{"my_own_recording", TumCamera::kUnknown, 525.0, 525.0, 319.5, 239.5}}) {
    const TumFixture fx(dir.path(), 1, c.name);
    const TumSequence s(fx.folder().string() + "/");  // a trailing slash changes nothing
    EXPECT_EQ(s.camera_model(), c.camera) << c.name;
    EXPECT_EQ(s.camera().fx, c.fx);
    EXPECT_EQ(s.camera().fy, c.fy);
    EXPECT_EQ(s.camera().cx, c.cx);
    EXPECT_EQ(s.camera().cy, c.cy);
    EXPECT_EQ(s.camera().width, 640);
    EXPECT_EQ(s.frame(0).camera.fx, c.fx);
    // TUM's calibrated lens of the raw images: freiburg1's and freiburg2's; freiburg3's images
    // come undistorted, and an unknown camera's lens is unknown.
    std::array<double, 5> lens{};
    if (c.camera == TumCamera::kFreiburg1) lens = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
    if (c.camera == TumCamera::kFreiburg2) lens = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
    EXPECT_EQ(s.camera().distortion, lens) << c.name;
    EXPECT_EQ(s.frame(0).camera.distortion, s.camera().distortion) << c.name;
    // Only freiburg1's Kinect has a measured profile (sensors/profiles/kinect1.yaml) for its frames to name.
    EXPECT_EQ(s.frame(0).sensor, c.camera == TumCamera::kFreiburg1 ? "kinect1" : "") << c.name;
  }
  const TumFixture fx(dir.path(), 1, "rgbd_dataset_freiburg1_o");
  SequenceOptions o;
  PinholeCamera c;
  c.fx = 500;
  c.fy = 501;
  c.cx = 320;
  c.cy = 240;
  o.intrinsics = c;
  const TumSequence s(fx.folder().string(), o);
  EXPECT_EQ(s.camera().fy, 501);
  EXPECT_EQ(s.camera().height, 480);
  c.fx = -1;
  o.intrinsics = c;
  EXPECT_THROW(TumSequence(fx.folder().string(), o), InputError);
}

// camera.txt (kestrel-sim writes one; a user writes one for a recording of any other camera)
// gives the intrinsics, the lens and the sensor profile, and wins over the folder's name
// (--intrinsics wins over it); without a sensor line the name's sensor stays. Its mounting is
// checked, not applied: a TUM folder's body frame is its camera's.
TEST(TumSequence, ACameraFileGivesTheCameraAndItsSensorOverTheFolderName) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 1, "rgbd_dataset_freiburg1_o");
  test::write_text(fx / "camera.txt",
                   "# fx fy cx cy width height k1 k2 p1 p2 k3\n500 501 320.5 240.5 640 480 0.1 -0.2 0 0 0.05\n"
                   "T_body_camera 0.1 0 0.05 0 0 0.7071068 0.7071068\nsensor simulator\n");
  const TumSequence s(fx.folder().string());
  EXPECT_TRUE(s.has_camera_file());
  EXPECT_EQ(s.camera().fx, 500);
  EXPECT_EQ(s.camera().cy, 240.5);
  EXPECT_EQ(s.camera().distortion, (std::array<double, 5>{0.1, -0.2, 0, 0, 0.05}));
  const RgbdFrame f = s.frame(0);
  EXPECT_EQ(f.sensor, "simulator");
  EXPECT_EQ(sensor_model_of_folder(fx.folder().string()), "simulator");
  EXPECT_TRUE(f.T_body_camera.isApprox(Eigen::Isometry3d::Identity()));
  SequenceOptions given;
  given.intrinsics = PinholeCamera::vga(510, 511, 319, 239);
  const TumSequence overridden(fx.folder().string(), given);
  EXPECT_EQ(overridden.camera().fx, 510);
  EXPECT_EQ(overridden.camera().distortion, (std::array<double, 5>{})) << "--intrinsics: no lens";
  EXPECT_EQ(overridden.frame(0).sensor, "simulator") << "the sensor is still camera.txt's";

  test::write_text(fx / "camera.txt", "500 501 320.5 240.5 640 480\n");
  const TumSequence plain(fx.folder().string());
  EXPECT_EQ(plain.frame(0).sensor, "kinect1") << "no sensor line: the folder name's";
  EXPECT_EQ(plain.camera().distortion, (std::array<double, 5>{})) << "the file's lens, not freiburg1's";
  EXPECT_TRUE(plain.frame(0).T_body_camera.isApprox(Eigen::Isometry3d::Identity()));

  // Images of another size than the file says: the frame is an InputError naming its line.
  test::write_text(fx / "camera.txt", "250 250 160 120 320 240\n");
  const TumSequence small(fx.folder().string());
  EXPECT_NE(input_error([&] { small.frame(0); }).find("rgb.txt"), std::string::npos);
}

// A bad camera.txt is an InputError naming the file and line: the family of a user's mistakes.
TEST(TumSequence, ABadCameraFileIsAnInputErrorNamingItsLine) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 1, "rgbd_dataset_freiburg1_o");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"500 501 320 240 640\n", "camera.txt:1: expected 'fx fy cx cy width height"},
      {"500 501 320 240 640 480 0.1\n", "camera.txt:1: expected"},
      {"500 nan 320 240 640 480\n", "camera.txt:1: 'nan' is not a finite number"},
      {"500 1e999 320 240 640 480\n", "camera.txt:1:"},
      {"-500 501 320 240 640 480\n", "camera.txt:1: the focal lengths must be > 0"},
      {"500 501 320 240 640.5 480\n", "camera.txt:1: the image size must be whole numbers"},
      {"500 501 320 240 0 480\n", "camera.txt:1: the image size"},
      {"500 501 320 240 99999 480\n", "camera.txt:1: the image size"},
      {"# nothing but a comment\n", "camera.txt: no 'fx fy cx cy width height' line"},
      {"\n500 501 320 240 640 480\nsensor\n", "camera.txt:3: expected 'sensor NAME'"},
      {"500 501 320 240 640 480\nsensor kinect1\nsensor simulator\n", "camera.txt:3: a second 'sensor' line"},
      {"500 501 320 240 640 480\nsensor kinect2\n", "camera.txt:2: sensor 'kinect2' is not a built-in profile"},
      {"500 501 320 240 640 480\nT_body_camera 0 0 0 0 0 0 2\n", "camera.txt:2: the quaternion's norm"},
      {"500 501 320 240 640 480\nT_body_camera 0 0 0 0 0 1\n", "camera.txt:2: expected 'T_body_camera"},
      {"500 501 320 240 640 480\nT_body_camera 0 0 0 0 0 0 1\nT_body_camera 0 0 0 0 0 0 1\n",
       "camera.txt:3: a second 'T_body_camera' line"},
      {"500 501 320 240 640 480\n500 501 320 240 640 480\n", "camera.txt:2: unknown line"},
      {"500 501 320 240 640 480\nlens 1 2\n", "camera.txt:2: unknown line 'lens 1 2'"},
      {"0.01 501 320 240 640 480\n", "camera.txt: implausible camera: fx"},
      {"500 501 1e6 240 640 480\n", "camera.txt: implausible camera: cx"},
      {"500 501 320 240 640 480\nT_body_camera 1000 0 0 0 0 0 1\n", "camera.txt: implausible camera: mounted"},
  };
  for (const auto& [text, expected] : cases) {
    test::write_text(fx / "camera.txt", text);
    const std::string e = input_error([&] { TumSequence(fx.folder().string()); });
    EXPECT_NE(e.find(expected), std::string::npos) << "got: " << e << "\nfor: " << text;
    EXPECT_EQ(input_error([&] { sensor_model_of_folder(fx.folder().string()); }), e) << text;
  }
}

TEST(TumSequence, CountsUnmatchedAndUnusedFrames) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 3);
  // An RGB image 50 ms after the last one has no depth; a depth image 25 ms before the first
  // RGB one is beyond 20 ms and stays unused.
  const int64_t late = TumFixture::rgb_utime(2) + 50000;
  const int64_t early = TumFixture::depth_utime(0) - 26000;
  std::filesystem::copy_file(fx / "rgb/1305031229.528748.png", fx / "rgb/late.png");
  std::filesystem::copy_file(fx / ("depth/" + format_seconds(TumFixture::depth_utime(0)) + ".png"), fx / "depth/early.png");
  fx.edit_line("rgb.txt", 0, format_seconds(late) + " rgb/late.png");
  std::string depth_list = "# depth maps\n" + format_seconds(early) + " depth/early.png\n";
  for (int k = 0; k < 3; ++k) {
    const std::string t = format_seconds(TumFixture::depth_utime(k));
    depth_list += t + " depth/" + t + ".png\n";
  }
  test::write_text(fx / "depth.txt", depth_list);
  const TumSequence s(fx.folder().string());
  EXPECT_EQ(s.size(), 3u);
  EXPECT_EQ(s.association().rgb_images, 4u);
  EXPECT_EQ(s.association().depth_images, 4u);
  EXPECT_EQ(s.association().unmatched_rgb, 1u);
  EXPECT_EQ(s.association().unused_depth, 1u);
  EXPECT_EQ(s.depth_utime(0), TumFixture::depth_utime(0));

}

// A folder whose lists pair nothing is an error naming the folder and the tolerance, not an
// empty sequence that every tool would run over and call a success.
TEST(TumSequence, NoPairedFrameIsAnInputErrorNamingTheFolderAndTolerance) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 3);
  SequenceOptions tight;
  tight.max_time_difference_us = 999;  // depth is 1000 us after RGB: nothing pairs
  const std::string e = input_error([&] { TumSequence(fx.folder().string(), tight); });
  EXPECT_EQ(e.rfind(fx.folder().string() + ": no RGB image has a depth image", 0), 0u) << e;
  EXPECT_NE(e.find("association tolerance of 0.000999 s"), std::string::npos) << e;
  EXPECT_NE(e.find("3 RGB images from " + format_seconds(TumFixture::rgb_utime(0))), std::string::npos) << e;
  EXPECT_NE(e.find("3 depth images from " + format_seconds(TumFixture::depth_utime(0))), std::string::npos) << e;
  tight.max_time_difference_us = 1000;  // inclusive: every frame pairs again
  EXPECT_EQ(TumSequence(fx.folder().string(), tight).size(), 3u);

  // Depth recorded a second later than the colour (another session's list): the default 20 ms.
  std::string depth_list = "# depth maps\n";
  for (int k = 0; k < 3; ++k) {
    const std::string file = "depth/" + format_seconds(TumFixture::depth_utime(k)) + ".png";
    depth_list += format_seconds(TumFixture::depth_utime(k) + 1000000) + " " + file + "\n";
  }
  test::write_text(fx / "depth.txt", depth_list);
  const std::string late = input_error([&] { TumSequence(fx.folder().string()); });
  EXPECT_NE(late.find("association tolerance of 0.020000 s"), std::string::npos) << late;
  EXPECT_EQ(late.find('\n'), std::string::npos) << "one line: " << late;
}

TEST(TumSequence, GroundTruthAndAccelerometerAreOptional) {
  test::TempDir dir;
  const TumFixture full(dir.path(), 2, "with");
  const TumSequence s(full.folder().string());
  EXPECT_TRUE(s.has_ground_truth());
  EXPECT_TRUE(s.has_accelerometer());
  EXPECT_EQ(static_cast<int>(s.accelerometer().size()), full.accel_samples());
  EXPECT_EQ(s.ground_truth().poses().front().utime, TumFixture::kT0 - 100000);

  test::TumFixtureOptions o;
  o.name = "without";
  o.frames = 2;
  o.ground_truth = false;
  o.accelerometer = false;
  const TumFixture bare(dir.path(), o);
  const TumSequence b(bare.folder().string());
  EXPECT_FALSE(b.has_ground_truth());
  EXPECT_FALSE(b.has_accelerometer());
  EXPECT_TRUE(b.ground_truth().empty());
  EXPECT_EQ(b.size(), 2u);
}

TEST(TumSequence, MissingFolderAndListsAreInputErrors) {
  test::TempDir dir;
  EXPECT_NE(input_error([&] { TumSequence((dir / "nope").string()); }).find("no such sequence folder"),
            std::string::npos);
  const TumFixture fx(dir.path(), 2);
  std::filesystem::remove(fx / "depth.txt");
  const std::string e = input_error([&] { TumSequence(fx.folder().string()); });
  EXPECT_NE(e.find((fx / "depth.txt").string() + ": cannot open image list"), std::string::npos) << e;
}

TEST(TumSequence, BadListsAndCompanionFilesNameFileAndLine) {
  test::TempDir dir;
  struct Case {
    const char* file;
    int line;
    const char* text;
    const char* expect;
  };
  for (const Case& c : {
           Case{"rgb.txt", 5, "1305031229.500000 rgb/x.png", "rgb.txt:5: timestamp 1305031229.500000 is not after"},
           Case{"rgb.txt", 4, "1305031229.528748", "rgb.txt:4: expected 'timestamp filename'"},
           Case{"rgb.txt", 0, "1305031300.0 rgb/missing.png", "rgb.txt:6: listed image 'rgb/missing.png' does not exist"},
           Case{"depth.txt", 4, "abc depth/x.png", "depth.txt:4: bad timestamp 'abc'"},
           Case{"groundtruth.txt", 5, "1305031229.438748 1 2 nan 0 0 0 1", "groundtruth.txt:5: non-finite value"},
           Case{"accelerometer.txt", 7, "1305031229.450000 1 nan 3", "accelerometer.txt:7: non-finite acceleration"},
           Case{"accelerometer.txt", 8, "1305031229.0 1 2 3", "accelerometer.txt:8: timestamp 1305031229.0 is not after"},
       }) {
    test::TempDir sub;
    const TumFixture fx(sub.path(), 2);
    fx.edit_line(c.file, c.line, c.text);
    const std::string e = input_error([&] { TumSequence(fx.folder().string()); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.file << ": " << e;
    EXPECT_NE(e.find(fx.folder().string()), std::string::npos) << "names the file: " << e;
  }
}

TEST(TumSequence, UndecodableOrWrongImagesFailInFrameNamingTheListLine) {
  test::TempDir dir;
  const std::string rgb1 = "rgb/" + format_seconds(TumFixture::rgb_utime(1)) + ".png";
  const std::string depth0 = "depth/" + format_seconds(TumFixture::depth_utime(0)) + ".png";
  struct Case {
    std::string file;
    std::function<void(const std::filesystem::path&)> damage;
    size_t frame;
    const char* expect;
  };
  const std::vector<Case> cases = {
      {rgb1, [](const auto& p) { test::write_text(p, "not a png at all"); }, 1, "rgb.txt:5: "},
      {rgb1,
       [](const auto& p) {
         std::string bytes(std::filesystem::file_size(p), '\0');
         std::ifstream(p, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
         test::write_text(p, bytes.substr(0, bytes.size() / 2));  // truncated PNG
       },
       1, "rgb.txt:5: "},
      {rgb1, [](const auto& p) { image::write_png(p.string(), cv::Mat(240, 320, CV_8UC3, cv::Scalar(1, 2, 3))); }, 1,
       "image is 320x240, expected 640x480"},
      {rgb1, [](const auto& p) { image::write_png(p.string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(9))); }, 1,
       "colour image is 8-bit, 1-channel, expected 8-bit, 3-channel"},
      {depth0, [](const auto& p) { image::write_png(p.string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(9))); }, 0,
       "depth.txt:4: " },
      {depth0, [](const auto& p) { image::write_png(p.string(), cv::Mat(480, 640, CV_16UC3, cv::Scalar(9, 9, 9))); }, 0,
       "depth image is 16-bit, 3-channel, expected 16-bit, 1-channel"},
  };
  for (const Case& c : cases) {
    test::TempDir sub;
    const TumFixture fx(sub.path(), 2);
    c.damage(fx / c.file);
    const TumSequence s(fx.folder().string());  // opening does not decode
    const std::string e = input_error([&] { s.frame(c.frame); });
    EXPECT_NE(e.find(c.expect), std::string::npos) << e;
    EXPECT_NE(e.find(c.file), std::string::npos) << "names the image: " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_NO_THROW(s.frame(1 - c.frame));  // the other frame is fine
  }
}

}  // namespace
}  // namespace kestrel::tum
