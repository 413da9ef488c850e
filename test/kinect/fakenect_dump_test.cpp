// The fakenect recording format (fakenect_dump.h), read back the way fakenect 0.5.3 reads
// it: INDEX.txt names parsed with "%c-%lf-%u", one header line skipped, raw bytes after it.

#include <gtest/gtest.h>

#include <libfreenect.h>

#include <cstdio>
#include <cstring>
#include <fstream>

#include "common/error.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/kinect/fakenect_dump.h"
#include "test/support/test_support.h"

namespace kestrel::kinect {
namespace {

std::vector<std::string> lines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string bytes_of(const std::filesystem::path& p) {
  std::string b(std::filesystem::file_size(p), '\0');
  std::ifstream(p, std::ios::binary).read(b.data(), static_cast<std::streamsize>(b.size()));
  return b;
}

TEST(FakenectDump, WritesWhatFakenectReads) {
  test::TempDir dir;
  const auto out = dir / "dump";
  cv::Mat rgb(480, 640, CV_8UC3);
  cv::Mat raw(480, 640, CV_16UC1);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uint8_t>(u), static_cast<uint8_t>(v), 7);
      raw.at<uint16_t>(v, u) = static_cast<uint16_t>((u + v) % 2048);
    }
  {
    FakenectDumpWriter w(out.string());
    w.add_accel(1305031104659000, Eigen::Vector3d(counts_to_mps2(-57), counts_to_mps2(653), counts_to_mps2(-468)));
    w.add_depth(1305031104659863, raw);
    w.add_rgb(1305031104675525, rgb);
    EXPECT_EQ(w.entries(), 3);
    EXPECT_THROW(w.add_rgb(1305031104600000, rgb), std::invalid_argument);  // back in time
    EXPECT_THROW(w.add_rgb(1305031104700000, cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
    w.close();
  }
  const auto index = lines(out / "INDEX.txt");
  ASSERT_EQ(index.size(), 3u);
  const char types[] = {'a', 'd', 'r'};
  const double seconds[] = {1305031104.659000, 1305031104.659863, 1305031104.675525};
  for (size_t i = 0; i < 3; ++i) {
    char type = 0;
    double t = 0;
    unsigned int ticks = 0;
    ASSERT_EQ(std::sscanf(index[i].c_str(), "%c-%lf-%u", &type, &t, &ticks), 3) << index[i];
    EXPECT_EQ(type, types[i]);
    EXPECT_NEAR(t, seconds[i], 1e-6);
    EXPECT_EQ(ticks, device_ticks(static_cast<int64_t>(std::llround(seconds[i] * 1e6))));
    ASSERT_TRUE(std::filesystem::is_regular_file(out / index[i])) << index[i];
  }
  EXPECT_EQ(index[2], "r-1305031104.675525-" + std::to_string(device_ticks(1305031104675525)) + ".ppm");

  const std::string accel = bytes_of(out / index[0]);
  ASSERT_EQ(accel.size(), sizeof(freenect_raw_tilt_state));
  freenect_raw_tilt_state state;
  std::memcpy(&state, accel.data(), sizeof state);
  EXPECT_EQ(state.accelerometer_x, -57);
  EXPECT_EQ(state.accelerometer_y, 653);
  EXPECT_EQ(state.accelerometer_z, -468);

  const std::string depth = bytes_of(out / index[1]);
  const std::string depth_header = "P5 640 480 65535\n";
  ASSERT_EQ(depth.size(), depth_header.size() + 640 * 480 * 2);
  EXPECT_EQ(depth.substr(0, depth_header.size()), depth_header);
  uint16_t value = 0;
  std::memcpy(&value, depth.data() + depth_header.size() + 2 * (3 * 640 + 5), 2);  // host order
  EXPECT_EQ(value, 8);

  const std::string colour = bytes_of(out / index[2]);
  const std::string rgb_header = "P6 640 480 255\n";
  ASSERT_EQ(colour.size(), rgb_header.size() + 640 * 480 * 3);
  EXPECT_EQ(colour.substr(0, rgb_header.size()), rgb_header);
  const size_t at = rgb_header.size() + 3 * (2 * 640 + 9);
  EXPECT_EQ(static_cast<uint8_t>(colour[at]), 9);  // R, G, B order
  EXPECT_EQ(static_cast<uint8_t>(colour[at + 1]), 2);
  EXPECT_EQ(static_cast<uint8_t>(colour[at + 2]), 7);
}

TEST(FakenectDump, NeverOverwritesADumpAndReportsUnwritableFolders) {
  test::TempDir dir;
  { FakenectDumpWriter(dir.path().string()).close(); }
  EXPECT_THROW(FakenectDumpWriter(dir.path().string()), InputError);
  EXPECT_THROW(FakenectDumpWriter("/proc/kestrel-no/dump"), InputError);
}

TEST(FakenectDump, DeviceTicksWrapLikeTheKinectClock) {
  EXPECT_EQ(device_ticks(0), 0u);
  EXPECT_EQ(device_ticks(1), 60u);
  EXPECT_EQ(device_ticks(71582788), static_cast<uint32_t>(71582788ULL * 60 % 4294967296ULL));
  EXPECT_EQ(device_ticks(1000000) - device_ticks(0), 60000000u);
}

}  // namespace
}  // namespace kestrel::kinect
