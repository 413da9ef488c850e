// PNG decoding of TUM images after a damaged one (issue 38's class "one bad compressed frame
// blinds the consumers", for the PNG decoder): every damaged file is an InputError naming the
// list line, and the good image read after it is exactly the one written.

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/image/image_io.h"
#include "drivers/tum/tum_images.h"
#include "test/support/test_support.h"

namespace kestrel::tum {
namespace {

std::string read_bytes(const std::filesystem::path& p) { return test::read_file(p); }

void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

struct Damaged {
  std::string what, bytes;
  bool must_fail;  // false where a flipped byte may still decode to some image
};

// Damaged copies of `good_png`: cut at several lengths, bytes flipped in the header, the image
// data and the end, random bytes after the signature.
std::vector<Damaged> damaged_copies(const std::string& good_png) {
  std::vector<Damaged> out;
  for (size_t n : {size_t{0}, size_t{8}, size_t{33}, good_png.size() / 2, good_png.size() - 20})
    out.push_back({"cut to " + std::to_string(n), good_png.substr(0, n), true});
  for (size_t pos : {size_t{1}, size_t{20}, size_t{40}, good_png.size() / 2, good_png.size() - 8}) {
    std::string s = good_png;
    s[pos] = static_cast<char>(s[pos] ^ 0x5a);
    out.push_back({"flipped at " + std::to_string(pos), s, false});
  }
  std::mt19937 rng(5);
  std::string noise(3000, '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  out.push_back({"random", good_png.substr(0, 8) + noise, true});
  return out;
}

TEST(TumImages, DamagedPngsAreRejectedAndTheNextImageReadsExactly) {
  test::TempDir dir;
  cv::Mat rgb(48, 64, CV_8UC3), depth(48, 64, CV_16UC1);
  for (int r = 0; r < 48; ++r) {
    for (int c = 0; c < 64; ++c) {
      rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(r * 5, c * 3, (r * c) % 256);
      depth.at<uint16_t>(r, c) = c % 7 == 0 ? 0 : static_cast<uint16_t>(5000 + 97 * r + c);
    }
  }
  const auto good_rgb = dir / "rgb.png", good_depth = dir / "depth.png", bad = dir / "bad.png";
  ASSERT_NO_THROW(image::write_png(good_rgb.string(), rgb));  // written B, G, R: read back as R, G, B = rgb
  ASSERT_NO_THROW(image::write_png(good_depth.string(), depth));
  cv::Mat expected_rgb;
  cv::cvtColor(rgb, expected_rgb, cv::COLOR_BGR2RGB);
  const ListedAt at{"rgb.txt", 4};

  for (const bool is_depth : {false, true}) {
    const auto& good = is_depth ? good_depth : good_rgb;
    for (const Damaged& d : damaged_copies(read_bytes(good))) {
      const std::string& what = d.what;
      write_bytes(bad, d.bytes);
      try {
        if (is_depth) {
          load_depth_raw(bad.string(), 64, 48, at);
        } else {
          load_rgb(bad.string(), 64, 48, at);
        }
        EXPECT_FALSE(d.must_fail) << what << ": accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("rgb.txt:4: ", 0), 0u) << what << ": " << e.what();
      }
      const cv::Mat again = is_depth ? load_depth_raw(good.string(), 64, 48, at) : load_rgb(good.string(), 64, 48, at);
      EXPECT_TRUE(same(again, is_depth ? depth : expected_rgb)) << (is_depth ? "depth" : "colour") << " after " << what;
    }
  }
}

}  // namespace
}  // namespace kestrel::tum
