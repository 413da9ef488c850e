// kestrel-slam as a user runs it: --help lists the options, bad options are exit code 2, a
// missing or corrupt input file is exit code 3 with one line naming it.

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

using ::kestrel::test::run;
using ::kestrel::test::TempDir;
using ::kestrel::test::tool;

TEST(SlamTool, HelpListsTheOptions) {
  const auto help = run({tool("slam"), "--help"});
  EXPECT_EQ(help.exit_code, kExitOk);
  for (const char* option : {"--keyframe-distance", "--loop-min-age", "--candidates", "--kernel", "--tum", "--vocabulary", "--sensor"}) {
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
  }
}

TEST(SlamTool, BadOptionsAreExitCode2) {
  EXPECT_EQ(run({tool("slam"), "--kernel", "tukey"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("slam"), "--keyframe-distance", "-1"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("slam"), "--candidates", "0"}).exit_code, kExitUsage);
  EXPECT_EQ(run({tool("slam"), "--sensor", "kinect2"}).exit_code, kExitUsage) << "simulator or kinect1";
  EXPECT_EQ(run({tool("slam"), "--out", "x.txt"}).exit_code, kExitUsage) << "--out only with --tum";
  EXPECT_EQ(run({tool("slam"), "--tum", "somewhere"}).exit_code, kExitUsage) << "--tum needs --out";
}

TEST(SlamTool, ACorruptVocabularyIsExitCode3NamingTheFile) {
  TempDir dir;
  std::ofstream(dir / "words.voc") << "not a vocabulary\n";
  const auto r = run({tool("slam"), "--vocabulary", (dir / "words.voc").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("words.voc: not a vocabulary file"), std::string::npos) << r.err;
}

TEST(SlamTool, AMissingVocabularyFileIsExitCode3) {
  TempDir dir;
  const auto r = run({tool("slam"), "--vocabulary", (dir / "none.voc").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput);
  EXPECT_NE(r.err.find("none.voc: cannot open"), std::string::npos) << r.err;
}

#if KESTREL_SLAM_OFFLINE
TEST(SlamTool, AMissingTumFolderIsExitCode3) {
  TempDir dir;
  const auto r = run({tool("slam"), "--tum", (dir / "none").string(), "--out", (dir / "t.txt").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
}
#endif

}  // namespace
}  // namespace kestrel::slam
