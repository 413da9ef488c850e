// kestrel-vo --tum as a user runs it, on TUM folders of the synthetic room (synthetic_tum.h): a
// run that produced nothing usable (no valid depth anywhere, no frame pairing with a depth
// image, unreadable lists or images) is exit 3 with one line naming the folder or file and
// writes no trajectory; a partly usable folder is scored and says how many frames were used.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/time.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"
#include "test/vo/synthetic_tum.h"

namespace kestrel::vo {
namespace {

namespace fs = std::filesystem;
using ::kestrel::test::run;
using ::kestrel::test::RunResult;
using ::kestrel::test::TempDir;

using test::kTumT0;
using test::TumFolderSpec;
using test::write_tum_folder;
using ::kestrel::test::write_text;

RunResult run_vo(const fs::path& folder, const fs::path& out, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> argv = {::kestrel::test::tool("vo").string(), "--tum", folder.string(), "--out", out.string()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return run(argv);
}

TEST(VoTool, NoValidDepthAnywhereExitsThreeAndWritesNothing) {
  TempDir dir;
  TumFolderSpec spec;
  spec.blank_depth_from = 0;
  const fs::path folder = write_tum_folder(dir.path(), spec);
  const RunResult r = run_vo(folder, dir / "t.txt", {"--stats", (dir / "s.json").string(), "-q"});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-vo: error: " + folder.string() +
                            ": nothing usable: 0 of 4 frames gave a motion (too little valid depth 4)",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.out.find("ATE"), std::string::npos) << "no accuracy for a run that estimated nothing: " << r.out;
  EXPECT_FALSE(fs::exists(dir / "t.txt"));
  EXPECT_FALSE(fs::exists(dir / "s.json"));
}

TEST(VoTool, NoFramePairingWithDepthExitsThreeNamingTheFolderAndTolerance) {
  TempDir dir;
  TumFolderSpec spec;
  spec.depth_shift_us = 10000000;  // 10 s later: no RGB image within TUM's 20 ms of any depth image
  const fs::path folder = write_tum_folder(dir.path(), spec);
  const RunResult r = run_vo(folder, dir / "t.txt", {"-q"});
  EXPECT_EQ(r.exit_code, kExitBadInput) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-vo: error: " + folder.string() + ": no RGB image has a depth image", 0), 0u)
      << r.err;
  EXPECT_NE(r.err.find("association tolerance of 0.020000 s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "t.txt"));
}

TEST(VoTool, APartlyUsableFolderIsScoredAndSaysHowManyFramesWereUsed) {
  TempDir dir;
  TumFolderSpec spec;
  spec.frames = 6;
  spec.blank_depth_from = 4;
  spec.extra_rgb = true;
  const fs::path folder = write_tum_folder(dir.path(), spec);
  const RunResult r = run_vo(folder, dir / "t.txt", {"--stats", (dir / "s.json").string()});
  ASSERT_EQ(r.exit_code, kExitOk) << r.out << r.err;
  EXPECT_NE(r.out.find("frames: 6 of 7 RGB images (1 without a depth image within 0.020000 s)\n"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("with a motion: 3 (50 %); by status: ok 3, no reference 1, too little valid depth 2\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("ATE RMSE: "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("3 of 6 frames gave no motion"), std::string::npos) << r.err;  // the first has no reference
  EXPECT_NE(r.err.find("1 RGB images have no depth image"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(::kestrel::test::read_file(dir / "s.json"));
  EXPECT_EQ(j.at("ok"), 3);
  EXPECT_EQ(j.at("by_status").at("too little valid depth"), 2);
  EXPECT_LT(j.at("accuracy").at("ate_rmse_m").get<double>(), 0.01);
  EXPECT_TRUE(fs::exists(dir / "t.txt"));
}

// A camera profile of the user's own (sensors/README.md): a file is taken as it is named; a
// copy of a built-in profile under another name runs exactly as the built-in one; a bad file is
// bad input naming the field, a name that is neither built in nor a file a usage error.
TEST(VoTool, TheCameraProfileComesFromAFileOfTheUsersOwn) {
  TempDir dir;
  TumFolderSpec spec;
  spec.frames = 6;
  const fs::path folder = write_tum_folder(dir.path(), spec);
  const RunResult builtin = run_vo(folder, dir / "a.txt", {"--sensor", "kinect1"});
  ASSERT_EQ(builtin.exit_code, kExitOk) << builtin.err;
  std::string copy = ::kestrel::test::read_file(::kestrel::test::source_dir() / "sensors/profiles/kinect1.yaml");
  copy.replace(copy.find("name: kinect1"), 13, "name: my_kinect");
  write_text(dir / "my_kinect.yaml", copy);
  const RunResult own = run_vo(folder, dir / "b.txt", {"--sensor", (dir / "my_kinect.yaml").string()});
  ASSERT_EQ(own.exit_code, kExitOk) << own.err;
  EXPECT_NE(own.err.find("camera profile: my_kinect"), std::string::npos) << own.err;
  EXPECT_EQ(::kestrel::test::read_file(dir / "a.txt"), ::kestrel::test::read_file(dir / "b.txt"));

  write_text(dir / "bad.yaml", "name: cam\ntiming: {rolling_shutter_readout_s: slow}\n");
  const RunResult bad = run_vo(folder, dir / "c.txt", {"--sensor", (dir / "bad.yaml").string()});
  EXPECT_EQ(bad.exit_code, kExitBadInput) << bad.err;
  EXPECT_NE(bad.err.find("timing.rolling_shutter_readout_s' is not a number"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "c.txt"));
  const RunResult unknown = run_vo(folder, dir / "d.txt", {"--sensor", "kinect2"});
  EXPECT_EQ(unknown.exit_code, kExitUsage) << unknown.err;
  EXPECT_NE(unknown.err.find("neither a built-in sensor profile (default, kinect1, simulator)"), std::string::npos) << unknown.err;
}

TEST(VoTool, UnreadableListsAndImagesExitThreeNamingTheFileAndLine) {
  struct Case {
    const char* what;
    std::function<void(const fs::path&)> damage;
    std::string expect;  // after "kestrel-vo: error: <folder>/"
  };
  const std::vector<Case> cases = {
      {"empty rgb.txt", [](const fs::path& f) { write_text(f / "rgb.txt", ""); }, "rgb.txt: lists no images"},
      {"truncated line", [](const fs::path& f) { write_text(f / "rgb.txt", format_seconds(kTumT0) + "\n"); },
       "rgb.txt:1: expected 'timestamp filename'"},
      {"NaN time stamp", [](const fs::path& f) { write_text(f / "depth.txt", "nan depth/0.png\n"); },
       "depth.txt:1: bad timestamp 'nan'"},
      {"infinite time stamp", [](const fs::path& f) { write_text(f / "depth.txt", "inf depth/0.png\n"); },
       "depth.txt:1: bad timestamp 'inf'"},
      {"negative time stamp", [](const fs::path& f) { write_text(f / "rgb.txt", "-1.0 rgb/0.png\n"); },
       "rgb.txt:1: bad timestamp '-1.0'"},
      {"truncated image", [](const fs::path& f) { fs::resize_file(f / "depth" / "1.png", 100); }, "depth.txt:3: "},
      {"empty image", [](const fs::path& f) { fs::resize_file(f / "rgb" / "2.png", 0); }, "rgb.txt:4: "},
  };
  for (const Case& c : cases) {
    TempDir dir;
    const fs::path folder = write_tum_folder(dir.path(), TumFolderSpec{});
    c.damage(folder);
    const RunResult r = run_vo(folder, dir / "t.txt", {"-q"});
    EXPECT_EQ(r.exit_code, kExitBadInput) << c.what << ": " << r.err;
    // libpng prints its own "libpng error: ..." line before OpenCV returns an empty image; ours
    // is then the one line of kestrel-vo's.
    const size_t ours = r.err.find("kestrel-vo: ");
    ASSERT_NE(ours, std::string::npos) << c.what << ": " << r.err;
    const std::string line = r.err.substr(ours);
    EXPECT_EQ(line.rfind("kestrel-vo: error: " + folder.string() + "/" + c.expect, 0), 0u) << c.what << ": " << r.err;
    EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "t.txt")) << c.what;
  }
}

// kestrel-vo-crossval (vo/cross_validation.h): each folder's best value scored on the other.
// On two recordings of the same synthetic motion every fold has a value and a held-out score.
TEST(VoCrossvalTool, TwoFoldsOverTwoFoldersAndEveryValueOnEach) {
  TempDir dir;
  TumFolderSpec spec;
  spec.frames = 8;
  const fs::path a = write_tum_folder(dir / "a", spec);
  const fs::path b = write_tum_folder(dir / "b", spec);
  const RunResult r = run({::kestrel::test::tool("vo-crossval").string(), "--tum", a.string(), "--tum", b.string(),
                           "--param", "dense.weight=0.4,2", "--param", "covariance.translation_floor_m=0.001,0.01",
                           "--objective", "ate", "-q"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.out << r.err;
  // The two folders share a name: they are told apart by the paths given.
  EXPECT_NE(r.out.find("| fitted on " + a.string() + ": value, held-out score (best there) | fitted on " + b.string()),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| `dense.weight` | ATE cm | 0.4 | "), std::string::npos) << "the default profile's value: " << r.out;
  EXPECT_NE(r.out.find("| `covariance.translation_floor_m` | ATE cm | "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("n/a"), std::string::npos) << "every value measured on both: " << r.out;
  EXPECT_NE(r.out.find("| 2 | "), std::string::npos) << "the grid of every value: " << r.out;
}

TEST(VoCrossvalTool, WhatItCannotUseIsAnErrorNamingIt) {
  TempDir dir;
  TumFolderSpec spec;
  spec.frames = 6;
  const fs::path a = write_tum_folder(dir / "a", spec);
  TumFolderSpec blank = spec;
  blank.blank_depth_from = 0;
  const fs::path b = write_tum_folder(dir / "b", blank);
  const fs::path c2 = write_tum_folder(dir / "c", spec);
  const std::string tool = ::kestrel::test::tool("vo-crossval").string();
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string says;
  };
  const std::vector<Case> cases{
      {{"--tum", a.string()}, kExitUsage, "two sequences or more"},
      {{"--tum", a.string(), "--tum", a.string() + "/"}, kExitUsage, "given twice"},
      {{"--tum", a.string(), "--tum", c2.string(), "--param", "no.such_key=1"}, kExitUsage, "no.such_key"},
      {{"--tum", a.string(), "--tum", c2.string(), "--param", "dense.weight"}, kExitUsage, "KEY=V1,V2"},
      {{"--tum", a.string(), "--tum", c2.string(), "--param", "dense.weight=1,,2"}, kExitUsage, "empty value"},
      {{"--tum", a.string(), "--tum", c2.string(), "--param", "dense.weight=-1"}, kExitUsage, "dense.weight"},
      {{"--tum", a.string(), "--tum", c2.string(), "--objective", "ATE", "--param", "dense.weight=1"}, kExitUsage, "'ATE'"},
      {{"--tum", a.string(), "--tum", c2.string(), "--objective", "nees"}, kExitUsage, "goes with --param"},
      // Usable folders, but a value with which the odometry measures nothing: its scores are n/a.
      {{"--tum", a.string(), "--tum", c2.string(), "--param", "min_features=0,1000000"}, kExitFailure, "not measured"},
      {{"--tum", a.string(), "--tum", b.string(), "--param", "dense.weight=1"}, kExitBadInput, b.string()},
      {{"--tum", a.string(), "--tum", (dir / "none").string(), "--param", "dense.weight=1"}, kExitBadInput, "none"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> argv{tool};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const RunResult r = run(argv);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.says << ": " << r.out << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace kestrel::vo
