// The text files of a TUM sequence: image lists and the accelerometer log.

#include <gtest/gtest.h>

#include "common/error.h"
#include "drivers/tum/tum_lists.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel::tum {
namespace {

struct BadText {
  const char* text;
  const char* expect;  // follows "<path>" in the error message
};

template <class Read>
void expect_errors(const std::vector<BadText>& cases, Read read) {
  test::TempDir dir;
  const std::string path = (dir / "list.txt").string();
  for (const auto& c : cases) {
    test::write_text(path, c.text);
    try {
      read(path);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + c.expect), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "not one line: " << e.what();
    }
  }
}

TEST(TumLists, ReadsImageListsExactly) {
  test::TempDir dir;
  test::write_text(dir / "rgb.txt",
                   "# color images\n# file: 'x.bag'\n# timestamp filename\n"
                   "1305031229.528748 rgb/1305031229.528748.png\n\n"
                   "1305031229.564425\trgb/b.png\r\n");
  const auto list = read_image_list((dir / "rgb.txt").string());
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].utime, 1305031229528748);
  EXPECT_EQ(list[0].file, "rgb/1305031229.528748.png");
  EXPECT_EQ(list[0].line, 4);
  EXPECT_EQ(list[1].utime, 1305031229564425);
  EXPECT_EQ(list[1].file, "rgb/b.png");
  EXPECT_EQ(list[1].line, 6);
}

TEST(TumLists, BadImageListsNameFileAndLine) {
  expect_errors(
      {
          {"# h\n1.0 a.png\n1.0 b.png\n", ":3: timestamp 1.0 is not after the previous one"},
          {"2.0 a.png\n1.0 b.png\n", ":2: timestamp 1.0 is not after"},
          {"1.0 a.png extra\n", ":1: expected 'timestamp filename'"},
          {"1.0\n", ":1: expected 'timestamp filename'"},
          {"x1.0 a.png\n", ":1: bad timestamp 'x1.0'"},
          {"nan a.png\n", ":1: bad timestamp 'nan'"},
          {"-1.0 a.png\n", ":1: bad timestamp '-1.0'"},
          {"# only comments\n\n", ": lists no images"},
      },
      [](const std::string& p) { read_image_list(p); });
  EXPECT_THROW(read_image_list("/nonexistent/rgb.txt"), InputError);
}

TEST(TumLists, ReadsTheAccelerometer) {
  test::TempDir dir;
  test::write_text(dir / "a.txt", "# accelerometer data\n1305031225.727159 0.682514 7.818977 -5.603800\n"
                                  "1305031225.730643 0.778306 7.818977 -5.603800\n");
  const auto samples = read_accelerometer((dir / "a.txt").string());
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[1].utime, 1305031225730643);
  EXPECT_DOUBLE_EQ(samples[1].accel_kinect.x(), 0.778306);
  EXPECT_DOUBLE_EQ(samples[1].accel_kinect.z(), -5.6038);
  test::write_text(dir / "empty.txt", "# no samples\n");
  EXPECT_TRUE(read_accelerometer((dir / "empty.txt").string()).empty());
}

TEST(TumLists, BadAccelerometerLogsNameFileAndLine) {
  expect_errors(
      {
          {"1.0 1 2 3\n1.0 1 2 3\n", ":2: timestamp 1.0 is not after"},
          {"1.0 1 2\n", ":1: expected 'timestamp ax ay az'"},
          {"1.0 1 2 x\n", ":1: expected 'timestamp ax ay az'"},
          {"1.0 1 nan 3\n", ":1: non-finite acceleration"},
          {"1.0 1 inf 3\n", ":1: non-finite acceleration"},
          {"1,0 1 2 3\n", ":1: bad timestamp '1,0'"},
      },
      [](const std::string& p) { read_accelerometer(p); });
  EXPECT_THROW(read_accelerometer("/nonexistent/accelerometer.txt"), InputError);
}

}  // namespace
}  // namespace kestrel::tum
