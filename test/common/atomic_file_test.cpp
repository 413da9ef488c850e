// AtomicFile (common/atomic_file.h): a write that fails or stops half-way leaves no target file
// (and an existing one as it was), success replaces the target whole, no temporary is left
// behind; devices and FIFOs are written in place, symbolic links followed; keep_aside keeps a
// file's bytes under a new name whatever replaces it.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/trajectory.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

size_t entries(const fs::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

// Runs `write` with the file-size limit at `limit` bytes (a full disk: a write past it fails
// with EFBIG instead of raising SIGXFSZ).
template <typename F>
void with_file_size_limit(rlim_t limit, F&& write) {
  rlimit old_limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit lowered = old_limit;
  lowered.rlim_cur = limit;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lowered), 0);
  try {
    write();
  } catch (...) {
    setrlimit(RLIMIT_FSIZE, &old_limit);
    std::signal(SIGXFSZ, old_handler);
    throw;
  }
  setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
}

TEST(AtomicFile, TheTargetAppearsOnlyOnCommitAndWhole) {
  test::TempDir dir;
  const std::string path = (dir / "out.txt").string();
  AtomicFile file(path);
  file.stream() << "first half\n";
  file.stream().flush();
  EXPECT_FALSE(fs::exists(path)) << "half-written content must not be at the target";
  EXPECT_TRUE(fs::exists(file.temp_path()));
  EXPECT_EQ(fs::path(file.temp_path()).parent_path(), dir.path()) << "same folder, so the rename is atomic";
  file.stream() << "second half\n";
  file.commit();
  EXPECT_EQ(test::read_file(path), "first half\nsecond half\n");
  EXPECT_EQ(entries(dir.path()), 1u) << "no temporary left behind";
}

TEST(AtomicFile, AWriterThatStopsHalfWayLeavesNoFileAndTheOldOneAsItWas) {
  test::TempDir dir;
  const std::string path = (dir / "map.txt").string();
  const auto write_and_throw = [&] {
    AtomicFile file(path);
    file.stream() << "half of a map";
    throw std::runtime_error("the run failed");
  };
  EXPECT_THROW(write_and_throw(), std::runtime_error);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(entries(dir.path()), 0u);

  std::ofstream(path) << "the previous run's map\n";
  EXPECT_THROW(write_and_throw(), std::runtime_error);
  EXPECT_EQ(test::read_file(path), "the previous run's map\n");
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, AWriteThatFailsOnAFullDiskLeavesNoFileAndTheOldOneAsItWas) {
  test::TempDir dir;
  const std::string path = (dir / "trajectory.txt").string();
  const std::string big(64 * 1024, 'x');
  const auto fail = [&] {
    with_file_size_limit(4096, [&] {
      try {
        write_file_atomically(path, big);
        ADD_FAILURE() << "a write past the file-size limit must fail";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(path + ": write failed"), std::string::npos) << e.what();
      }
    });
  };
  fail();
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(entries(dir.path()), 0u);

  std::ofstream(path) << "kept\n";
  fail();
  EXPECT_EQ(test::read_file(path), "kept\n");
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, SuccessReplacesAnExistingFileAndKeepsItsPermissions) {
  test::TempDir dir;
  const std::string path = (dir / "report.txt").string();
  std::ofstream(path) << "an old report that is much longer than the new one\n";
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_file_atomically(path, std::string("new\n"));
  EXPECT_EQ(test::read_file(path), "new\n");
  EXPECT_EQ(fs::status(path).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, ALinkIsFollowedAndAFifoIsWrittenInPlace) {
  test::TempDir dir;
  std::ofstream(dir / "real.txt") << "old\n";
  fs::create_symlink("real.txt", dir / "link.txt");
  write_file_atomically((dir / "link.txt").string(), std::string("through the link\n"));
  EXPECT_TRUE(fs::is_symlink(dir / "link.txt")) << "the link stays a link";
  EXPECT_EQ(test::read_file(dir / "real.txt"), "through the link\n");

  // Renaming over a FIFO (or /dev/null) would replace it with a file: it is written instead.
  const std::string fifo = (dir / "pipe").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  write_file_atomically(fifo, std::string("abc"));
  char got[8] = {};
  const ssize_t n = ::read(reader, got, sizeof got);
  ::close(reader);
  EXPECT_EQ(std::string(got, n > 0 ? static_cast<size_t>(n) : 0), "abc");
  EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST(AtomicFile, AFolderOrAMissingFolderIsAnErrorNamingThePath) {
  test::TempDir dir;
  try {
    AtomicFile file(dir.path().string());
    FAIL() << "a folder is not a file to write";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  const std::string missing = (dir / "no-such-folder" / "out.txt").string();
  try {
    AtomicFile file(missing);
    FAIL() << "a file in a missing folder cannot be written";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing + ": cannot write in ", 0), 0u) << e.what();
  }
}

// What is about to be replaced is first kept under a new name, and stays as it was.
TEST(AtomicFile, KeepAsideKeepsTheBytesThatAReplacementWouldLose) {
  test::TempDir dir;
  const std::string path = (dir / "mapper.journal").string();
  std::ofstream(path) << "the flight\n";
  const std::string first = keep_aside(path, "reset");
  EXPECT_EQ(first.rfind(path + ".reset-", 0), 0u) << first;
  write_file_atomically(path, std::string("a new journal\n"));
  EXPECT_EQ(test::read_file(first), "the flight\n");
  EXPECT_EQ(test::read_file(path), "a new journal\n");
  const std::string second = keep_aside(path, "reset");
  EXPECT_NE(second, first);
  EXPECT_EQ(test::read_file(second), "a new journal\n");

  // Through a symbolic link, the file is kept, not a second link that would follow the new one.
  fs::create_symlink("mapper.journal", dir / "current");
  const std::string third = keep_aside((dir / "current").string(), "damaged");
  EXPECT_FALSE(fs::is_symlink(third));
  write_file_atomically((dir / "current").string(), std::string("newer\n"));
  EXPECT_EQ(test::read_file(third), "a new journal\n");
  EXPECT_EQ(test::read_file(path), "newer\n");
  EXPECT_THROW(keep_aside((dir / "missing").string(), "reset"), InputError);
}

// The TUM trajectory writer (vo, slam, estimate, eval) goes through it.
TEST(AtomicFile, ATrajectoryWriteThatFailsLeavesTheOldTrajectory) {
  test::TempDir dir;
  const std::string path = (dir / "vo.txt").string();
  Trajectory t;
  for (int i = 0; i < 2000; ++i) t.push_back(1000000 + 33333 * i, Eigen::Isometry3d::Identity());
  write_tum_trajectory(path, t);
  const std::string whole = test::read_file(path);
  ASSERT_GT(whole.size(), 20000u);
  Trajectory longer = t;
  longer.push_back(1000000 + 33333 * 2000, Eigen::Isometry3d::Identity());
  with_file_size_limit(8192, [&] { EXPECT_THROW(write_tum_trajectory(path, longer), InputError); });
  EXPECT_EQ(test::read_file(path), whole) << "the last good file, not a cut one";
  EXPECT_EQ(entries(dir.path()), 1u);
}

}  // namespace
}  // namespace kestrel
