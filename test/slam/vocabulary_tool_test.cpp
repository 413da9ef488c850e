// kestrel-slam-vocabulary as a user runs it: it trains on a TUM folder and writes a file that
// kestrel-slam's --vocabulary loads; bad options are exit code 2; a missing folder or images
// without features are exit code 3 with one line naming the problem.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/error.h"
#include "common/image/image_io.h"
#include "slam/place/vocabulary.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel::slam {
namespace {

using ::kestrel::test::run;
using ::kestrel::test::TempDir;
using ::kestrel::test::tool;

// Replaces every colour image of `folder` with random 8x8 blocks (texture: `textured`) or a
// uniform grey.
void paint_images(const std::filesystem::path& folder, bool textured) {
  std::ifstream list(folder / "rgb.txt");
  std::string line;
  cv::RNG rng(5);
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string stamp, file;
    fields >> stamp >> file;
    cv::Mat image(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
    if (textured) {
      for (int r = 0; r < image.rows; r += 8)
        for (int c = 0; c < image.cols; c += 8) image(cv::Rect(c, r, 8, 8)).setTo(cv::Scalar::all(rng.uniform(0, 256)));
    }
    ASSERT_NO_THROW(image::write_png((folder / file).string(), image)) << file;
  }
}

TEST(SlamVocabularyTool, TrainsAFileThatSlamLoads) {
  TempDir dir;
  const test::TumFixture tum(dir.path(), 3);
  paint_images(tum.folder(), true);
  const std::string out = (dir / "words.voc").string();
  const auto r = run({tool("slam-vocabulary"), "--tum", tum.folder().string(), "--out", out, "--branching", "4",
                      "--depth", "3"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("images: 3"), std::string::npos) << r.out;
  const Vocabulary v = Vocabulary::load(out);
  EXPECT_EQ(v.branching(), 4);
  EXPECT_GT(v.num_words(), 16);
  EXPECT_LE(v.num_words(), 64);
}

TEST(SlamVocabularyTool, BadOptionsAreExitCode2) {
  EXPECT_EQ(run({tool("slam-vocabulary"), "--out", "x.voc"}).exit_code, kExitUsage) << "--tum is required";
  EXPECT_EQ(run({tool("slam-vocabulary"), "--tum", "d"}).exit_code, kExitUsage) << "--out is required";
  EXPECT_EQ(run({tool("slam-vocabulary"), "--tum", "d", "--out", "x.voc", "--branching", "1"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("slam-vocabulary"), "--tum", "d", "--out", "x.voc", "--every", "0"}).exit_code, kExitUsage);
}

TEST(SlamVocabularyTool, AMissingFolderIsExitCode3NamingIt) {
  TempDir dir;
  const auto r = run({tool("slam-vocabulary"), "--tum", (dir / "none").string(), "--out", (dir / "w.voc").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
}

TEST(SlamVocabularyTool, ImagesWithoutFeaturesAreExitCode3) {
  TempDir dir;
  const test::TumFixture tum(dir.path(), 2);
  paint_images(tum.folder(), false);
  const auto r = run({tool("slam-vocabulary"), "--tum", tum.folder().string(), "--out", (dir / "w.voc").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("no ORB features"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "w.voc"));
}

}  // namespace
}  // namespace kestrel::slam
