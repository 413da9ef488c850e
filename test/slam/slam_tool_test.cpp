// kestrel-slam as a user runs it: --help lists the options, bad options are exit code 2, a
// missing or corrupt input file is exit code 3 with one line naming it, and so is a --tum run
// that estimated nothing, which writes no trajectory (as kestrel-vo --tum).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "test/support/test_support.h"
#if KESTREL_SLAM_OFFLINE
#include "common/trajectory.h"
#include "test/vo/synthetic_tum.h"
#endif

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
  EXPECT_EQ(run({tool("slam"), "--sensor", "kinect2"}).exit_code, kExitUsage) << "default, kinect1 or simulator";
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

TEST(SlamTool, ADamagedOrMissingMapIsExitCode3NamingItBeforeAnythingRuns) {
  TempDir dir;
  std::filesystem::create_directories(dir / "map");
  std::ofstream(dir / "map" / "slam.map") << "KESTREL-SLAM-MAP but not one\n";
  for (const auto& folder : {dir / "map", dir / "none"}) {
    const auto r = run({tool("slam"), "--map", folder.string()});  // the process: refused before it joins LCM
    EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
    EXPECT_NE(r.err.find((folder / "slam.map").string()), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// `kestrel save-map` asks a running kestrel-slam to save now; one without --save-map says it
// cannot, and save-map says so (exit 1) rather than waiting for ever.
TEST(SlamTool, SaveMapAsksARunningSlamToSaveItsMapNow) {
  if (!::kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  TempDir dir;
  const std::string slam = tool("slam").string(), save = tool("save-map").string(), map = (dir / "m").string();
  // Before any keyframe there is nothing to save, and it says so.
  const auto empty = ::kestrel::test::run_isolated(
      "'" + slam + "' -q --save-map '" + map + "' & S=$!; '" + save + "' --timeout 20; R=$?; kill -INT $S; wait $S; exit $R",
      60.0);
  EXPECT_EQ(empty.exit_code, kExitFailure) << empty.out << empty.err;
  EXPECT_NE(empty.out.find("no keyframe yet"), std::string::npos) << empty.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "m" / "slam.map")) << "a map of nothing is not written, on exit either";
  // After 3 s of the sim's room through the VO: saved.
  const auto saved = ::kestrel::test::run_isolated(
      "'" + tool("vo").string() + "' -q & V=$!; '" + slam + "' -q --save-map '" + map + "' & S=$!; sleep 0.5; '" +
          tool("sim").string() + "' -q --world room --flight figure8 --duration 3 > /dev/null; sleep 1; '" + save +
          "' --timeout 20; R=$?; kill -INT $S $V; wait $S $V; exit $R",
      90.0);
  EXPECT_EQ(saved.exit_code, kExitOk) << saved.out << saved.err;
  EXPECT_NE(saved.out.find("map saved for request"), std::string::npos) << saved.out;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "m" / "slam.map"));
  const auto refused = ::kestrel::test::run_isolated(
      "'" + slam + "' -q & S=$!; '" + save + "' --timeout 4; R=$?; kill -INT $S; wait $S; exit $R", 60.0);
  EXPECT_EQ(refused.exit_code, kExitFailure) << refused.out << refused.err;
  EXPECT_NE(refused.err.find("was it started with --save-map?"), std::string::npos) << refused.err;
}

#if KESTREL_SLAM_OFFLINE
namespace fs = std::filesystem;
using ::kestrel::test::RunResult;

TEST(SlamTool, AMissingTumFolderIsExitCode3) {
  TempDir dir;
  const auto r = run({tool("slam"), "--tum", (dir / "none").string(), "--out", (dir / "t.txt").string()});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
}

// Both trajectories asked for, into `dir`: slam.txt and vo.txt.
RunResult run_slam_on(const fs::path& folder, const TempDir& dir) {
  return run({tool("slam"), "--tum", folder.string(), "--out", (dir / "slam.txt").string(), "--vo-out",
              (dir / "vo.txt").string(), "-q"});
}

// A trajectory of the first frame's identity pose alone, or of none, would read as a result.
TEST(SlamTool, ATumRunWithoutAMotionIsExitCode3NamingTheFolderAndWritesNothing) {
  TempDir dir;
  vo::test::TumFolderSpec spec;
  spec.blank_depth_from = 0;  // no depth reading in any frame: the odometry gives no motion
  const fs::path folder = vo::test::write_tum_folder(dir.path(), spec);
  const RunResult r = run_slam_on(folder, dir);
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-slam: error: " + folder.string() +
                            ": nothing usable: 0 of 4 frames gave a motion (too little valid depth 4)",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out.find("keyframes:"), std::string::npos) << "no figures of a run that estimated nothing: " << r.out;
  EXPECT_FALSE(fs::exists(dir / "slam.txt"));
  EXPECT_FALSE(fs::exists(dir / "vo.txt"));
}

TEST(SlamTool, ATumFolderWhereNoFramePairsIsExitCode3AndWritesNothing) {
  TempDir dir;
  vo::test::TumFolderSpec spec;
  spec.depth_shift_us = 10000000;  // 10 s later: no RGB image within TUM's 20 ms of any depth image
  const fs::path folder = vo::test::write_tum_folder(dir.path(), spec);
  const RunResult r = run_slam_on(folder, dir);
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-slam: error: " + folder.string() + ": no RGB image has a depth image", 0), 0u)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "slam.txt"));
  EXPECT_FALSE(fs::exists(dir / "vo.txt"));
}

// The refusal above is of runs without a motion only: the same room with its depth is a run.
TEST(SlamTool, AUsableTumFolderWritesBothTrajectoriesWithEveryFrame) {
  TempDir dir;
  const fs::path folder = vo::test::write_tum_folder(dir.path(), vo::test::TumFolderSpec{});
  const RunResult r = run_slam_on(folder, dir);
  ASSERT_EQ(r.exit_code, kExitOk) << r.out << r.err;
  EXPECT_NE(r.out.find("frames: 4, with a pose: 4\n"), std::string::npos) << r.out;
  EXPECT_EQ(read_tum_trajectory((dir / "slam.txt").string()).size(), 4u);
  EXPECT_EQ(read_tum_trajectory((dir / "vo.txt").string()).size(), 4u);
}

// A map saved by one run is where the next starts: placed in it by relocalisation, its
// trajectory in the map's world (here the same room from the same start: the same poses).
TEST(SlamTool, ASavedMapIsWhereTheNextRunIsPlaced) {
  TempDir dir;
  vo::test::TumFolderSpec spec;
  spec.frames = 12;
  const fs::path folder = vo::test::write_tum_folder(dir.path(), spec);
  const RunResult first = run({tool("slam"), "--tum", folder.string(), "--out", (dir / "first.txt").string(),
                               "--save-map", (dir / "map").string()});
  ASSERT_EQ(first.exit_code, kExitOk) << first.out << first.err;
  ASSERT_TRUE(fs::is_regular_file(dir / "map" / "slam.map"));
  const RunResult second = run({tool("slam"), "--tum", folder.string(), "--out", (dir / "second.txt").string(),
                                "--map", (dir / "map").string(), "--save-map", (dir / "map").string()});
  ASSERT_EQ(second.exit_code, kExitOk) << second.out << second.err;
  EXPECT_NE(second.err.find("relocalised at frame 2 of those tried"), std::string::npos) << second.err;
  const Trajectory a = read_tum_trajectory((dir / "first.txt").string());
  const Trajectory b = read_tum_trajectory((dir / "second.txt").string());
  ASSERT_GE(b.size(), 8u);
  for (const StampedPose& p : b.poses()) {
    const auto q = a.at(p.utime, 0);
    ASSERT_TRUE(q);
    EXPECT_LT((q->translation() - p.T.translation()).norm(), 0.01) << p.utime;
  }
  // Saved again over the map it read (atomically): the second run added no keyframe over the
  // ground the first covered, so the map is still one session's.
  EXPECT_NE(second.err.find("map saved: " + (dir / "map" / "slam.map").string() + " (1 keyframes, 1 session(s))"),
            std::string::npos)
      << second.err;
}
#endif

}  // namespace
}  // namespace kestrel::slam
