// The mapper's journal on damaged files (keyframe_journal.h): cut short in a record, a flipped
// byte, a zeroed stretch across records, a garbage header. Every intact record is read, before
// and after the damage; a mapper started on it keeps the damaged file whole aside (its original
// bytes) and goes on in a fresh journal made of exactly the intact records' bytes; nothing is
// ever cut in place, and a file that is no journal, or not as it was read, is never written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/transport/convert.h"
#include "mapper/keyframe_journal.h"
#include "mapper/map_node.h"
#include "mapper/scan.h"
#include "test/mapper/scene.h"
#include "test/support/test_support.h"

namespace kestrel::mapper {
namespace {

namespace fs = std::filesystem;

kestrel::slam_keyframe_t keyframe(int64_t id, int64_t utime, double x_m) {
  kestrel::slam_keyframe_t k{};
  k.id = id;
  k.utime = utime;
  k.T_world_camera = transport::to_message(test::look_at({-1.2 + x_m, 0.013, 1.2}, {2.0, 0.3, 0.7}));
  k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
  return k;
}

// A journal of keyframes 0, 1, a graph moving keyframe 0, keyframes 2, 3. `ends[i]` is the
// file's size after the header (i = 0) and after each record (i = 1..5).
struct Written {
  std::string path;
  std::vector<uint64_t> ends;
  std::string bytes;
};

Written write_journal(const fs::path& dir) {
  const test::Scene scene = test::room_with_a_box();
  Written w;
  w.path = (dir / "mapper.journal").string();
  JournalWriter journal(w.path);
  w.ends.push_back(journal.bytes());
  const auto add_keyframe = [&](int64_t id) {
    const int64_t utime = 100000 * (id + 1);
    const kestrel::slam_keyframe_t k = keyframe(id, utime, 0.1 * static_cast<double>(id));
    const RgbdFrame frame = scene.render(test::kinect_camera(160, 120),
                                         transport::from_message(k.T_world_camera, "test"), utime);
    journal.keyframe(k, decimate(frame, 5));
    w.ends.push_back(journal.bytes());
  };
  add_keyframe(0);
  add_keyframe(1);
  kestrel::slam_graph_t moved{};
  moved.revision = 2;
  moved.keyframes.push_back(keyframe(0, 100000, 0.05));
  moved.num_keyframes = 1;
  journal.graph(moved);
  w.ends.push_back(journal.bytes());
  add_keyframe(2);
  add_keyframe(3);
  w.bytes = kestrel::test::read_file(w.path);
  EXPECT_EQ(w.bytes.size(), w.ends.back());
  return w;
}

void overwrite(const std::string& path, uint64_t at, const std::string& bytes) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(at));
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// "K0 G K3": the kind and, for keyframes, the id of each record read.
std::string summary(const JournalContents& c) {
  std::string s;
  for (const JournalRecord& r : c.records) {
    if (!s.empty()) s += ' ';
    s += r.kind == JournalRecord::Kind::kGraph ? "G" : "K" + std::to_string(r.keyframe.id);
  }
  return s;
}

// A mapper started on the damaged journal at `w.path` (whose bytes are now `damaged`): it
// restores `keyframes`, keeps `damaged` whole aside and continues in a journal of exactly
// `expected_fresh` (the header and the intact records' bytes), which reads whole.
void expect_kept_and_continued(const Written& w, const std::string& damaged, int64_t keyframes,
                               const std::string& expected_fresh, const std::string& expected_records) {
  NodeOptions options;
  options.journal_path = w.path;
  std::string aside;
  {
    MapNode node(options);
    EXPECT_EQ(node.stats().keyframes_restored, keyframes);
    EXPECT_NE(node.journal_damage(), "");
    aside = node.journal_kept_aside();
  }
  ASSERT_NE(aside, "");
  EXPECT_EQ(fs::path(aside).parent_path(), fs::path(w.path).parent_path());
  EXPECT_EQ(fs::path(aside).filename().string().rfind("mapper.journal.damaged-", 0), 0u) << aside;
  EXPECT_TRUE(kestrel::test::read_file(aside) == damaged) << "the damaged file is kept byte for byte";
  EXPECT_TRUE(kestrel::test::read_file(w.path) == expected_fresh) << "the intact records, byte for byte";
  const JournalContents fresh = read_journal(w.path);
  EXPECT_EQ(fresh.damage, "");
  EXPECT_EQ(summary(fresh), expected_records);

  // It is appended to, and the kept file does not change with it.
  {
    JournalWriter writer(w.path, fresh);
    kestrel::slam_graph_t later{};
    later.revision = 9;
    writer.graph(later);
  }
  EXPECT_EQ(summary(read_journal(w.path)), expected_records + " G");
  EXPECT_TRUE(kestrel::test::read_file(aside) == damaged);
  // Started again on the now whole journal: nothing more is set aside.
  MapNode again(options);
  EXPECT_EQ(again.journal_damage(), "");
  EXPECT_EQ(again.journal_kept_aside(), "");
}

std::string slice(const std::string& s, uint64_t begin, uint64_t end) { return s.substr(begin, end - begin); }

TEST(KeyframeJournal, AJournalCutShortInARecordKeepsEveryRecordBeforeAndTheOriginalBytes) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  fs::resize_file(w.path, (w.ends[4] + w.ends[5]) / 2);  // killed writing keyframe 3
  const std::string damaged = kestrel::test::read_file(w.path);
  const JournalContents c = read_journal(w.path);
  EXPECT_EQ(summary(c), "K0 K1 G K2");
  EXPECT_EQ(c.intact_bytes, w.ends[4]);
  EXPECT_NE(c.damage.find("record 4 is cut short"), std::string::npos) << c.damage;
  expect_kept_and_continued(w, damaged, 3, w.bytes.substr(0, w.ends[4]), "K0 K1 G K2");
}

TEST(KeyframeJournal, AFlippedByteLosesOnlyTheRecordItIsIn) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  const uint64_t at = (w.ends[1] + w.ends[2]) / 2;  // inside keyframe 1's frame
  overwrite(w.path, at, std::string(1, static_cast<char>(w.bytes[at] ^ 0x10)));
  const std::string damaged = kestrel::test::read_file(w.path);
  const JournalContents c = read_journal(w.path);
  EXPECT_EQ(summary(c), "K0 G K2 K3") << "read on after the damage";
  EXPECT_NE(c.damage.find("record 1 fails its CRC"), std::string::npos) << c.damage;
  EXPECT_EQ(c.damaged_stretches, 1);
  EXPECT_EQ(c.skipped_bytes, w.ends[2] - w.ends[1]);
  expect_kept_and_continued(w, damaged, 3, slice(w.bytes, 0, w.ends[1]) + slice(w.bytes, w.ends[2], w.ends[5]),
                            "K0 G K2 K3");
}

TEST(KeyframeJournal, AZeroedStretchAcrossRecordsLosesOnlyThoseRecords) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  // A zeroed block from inside keyframe 1 to inside keyframe 2 (the graph between is lost).
  const uint64_t from = (w.ends[1] + w.ends[2]) / 2, to = (w.ends[3] + w.ends[4]) / 2;
  overwrite(w.path, from, std::string(to - from, '\0'));
  const std::string damaged = kestrel::test::read_file(w.path);
  const JournalContents c = read_journal(w.path);
  EXPECT_EQ(summary(c), "K0 K3");
  EXPECT_EQ(c.skipped_bytes, w.ends[4] - w.ends[1]);
  expect_kept_and_continued(w, damaged, 2, slice(w.bytes, 0, w.ends[1]) + slice(w.bytes, w.ends[4], w.ends[5]),
                            "K0 K3");
}

TEST(KeyframeJournal, AGarbageHeaderKeepsEveryRecord) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  overwrite(w.path, 0, "\x7f garbage \x01\x02");
  const std::string damaged = kestrel::test::read_file(w.path);
  const JournalContents c = read_journal(w.path);
  EXPECT_EQ(summary(c), "K0 K1 G K2 K3");
  EXPECT_EQ(c.damage.rfind("its header is damaged", 0), 0u) << c.damage;
  expect_kept_and_continued(w, damaged, 4, w.bytes, "K0 K1 G K2 K3");
}

// Random bytes or text, with no header and no intact record: not a journal, never written.
TEST(KeyframeJournal, AFileWithNoHeaderAndNoIntactRecordIsNotAJournalAndIsLeftAlone) {
  kestrel::test::TempDir dir;
  const std::string path = (dir / "photo.jpg").string();
  std::mt19937 random(7);
  std::string noise(256 * 1024, '\0');
  for (char& c : noise) c = static_cast<char>(random() & 0xFF);
  std::ofstream(path, std::ios::binary) << noise;
  NodeOptions options;
  options.journal_path = path;
  try {
    MapNode node(options);
    FAIL() << "random bytes are not a journal";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("photo.jpg: not a kestrel mapper journal"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(kestrel::test::read_file(path) == noise);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

// The writer takes what read_journal found as proof of what is on disk: a journal it did not
// read (or that changed since) is refused, not started again over.
TEST(KeyframeJournal, AWriterNeverWritesOverAJournalItDidNotRead) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  EXPECT_THROW(JournalWriter{w.path}, InputError);
  JournalContents stale = read_journal(w.path);
  fs::resize_file(w.path, w.ends[3]);
  EXPECT_THROW(JournalWriter(w.path, stale), InputError);
  EXPECT_TRUE(kestrel::test::read_file(w.path) == w.bytes.substr(0, w.ends[3]));
}

}  // namespace
}  // namespace kestrel::mapper
