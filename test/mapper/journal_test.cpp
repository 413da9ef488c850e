// The mapper's journal on damaged files (keyframe_journal.h): cut short in a record, a flipped
// byte, a zeroed stretch across records, a garbage header. Every intact record is read, before
// and after the damage; a mapper started on it keeps the damaged file whole aside (its original
// bytes) and goes on in a fresh journal made of exactly the intact records' bytes; nothing is
// ever cut in place, and a file that is no journal, or not as it was read, is never written.
// Of the journals set aside only the newest of each kind stay, and only files the writer set
// aside are ever deleted. Compaction keeps each keyframe as placed, in one rename, or changes
// nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
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
    switch (r.kind) {
      case JournalRecord::Kind::kGraph: s += "G"; break;
      case JournalRecord::Kind::kKeyframe: s += "K" + std::to_string(r.keyframe.id); break;
      case JournalRecord::Kind::kPinned: s += "P" + std::to_string(r.frame.utime / 100000); break;
      case JournalRecord::Kind::kReleased: s += "R"; break;
    }
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

// The bytes a fresh journal of `records` (a summary, "K0 G K3") holds: the header, then each
// of those records of w's journal, byte for byte.
std::string fresh_journal_of(const Written& w, const std::string& records) {
  static const std::vector<std::string> written_order = {"K0", "K1", "G", "K2", "K3"};
  std::string bytes = slice(w.bytes, 0, w.ends[0]);
  std::istringstream names(records);
  for (std::string name; names >> name;) {
    const auto at = std::find(written_order.begin(), written_order.end(), name);
    if (at == written_order.end()) {
      ADD_FAILURE() << "no record " << name << " in the journal written";
      continue;
    }
    const size_t i = static_cast<size_t>(at - written_order.begin());
    bytes += slice(w.bytes, w.ends[i], w.ends[i + 1]);
  }
  return bytes;
}

// A kind of damage done to write_journal()'s file, and what a reader must make of it.
struct Damage {
  const char* name;
  void (*apply)(const Written& w);
  const char* records;     // the records still intact, as summary() gives them
  int64_t keyframes;       // of those, keyframes: what a mapper restores
  bool header_damaged;     // then the header is not among the intact bytes
  const char* damage_starts;  // how JournalContents::damage begins (the first damage)
};

const std::vector<Damage>& damages() {
  static const std::vector<Damage> table = {
      // Killed writing keyframe 3: every record before it is kept.
      {"cut short in a record",
       [](const Written& w) { fs::resize_file(w.path, (w.ends[4] + w.ends[5]) / 2); }, "K0 K1 G K2", 3, false,
       "record 4 is cut short"},
      // A flipped byte inside keyframe 1's frame loses only that record; reading goes on after it.
      {"a flipped byte",
       [](const Written& w) {
         const uint64_t at = (w.ends[1] + w.ends[2]) / 2;
         overwrite(w.path, at, std::string(1, static_cast<char>(w.bytes[at] ^ 0x10)));
       },
       "K0 G K2 K3", 3, false, "record 1 fails its CRC"},
      // A zeroed block from inside keyframe 1 to inside keyframe 2: the graph between is lost too.
      {"a zeroed stretch across records",
       [](const Written& w) {
         const uint64_t from = (w.ends[1] + w.ends[2]) / 2, to = (w.ends[3] + w.ends[4]) / 2;
         overwrite(w.path, from, std::string(to - from, '\0'));
       },
       "K0 K3", 2, false, "record 1 fails its CRC"},
      // Every record is kept; the fresh journal gets a whole header again.
      {"a garbage header", [](const Written& w) { overwrite(w.path, 0, "\x7f garbage \x01\x02"); }, "K0 K1 G K2 K3", 4,
       true, "its header is damaged"},
  };
  return table;
}

// Each kind of damage loses only the records it is in, and only their bytes are unreadable;
// a mapper started on the journal keeps the damaged file whole aside (its original bytes) and
// goes on in a fresh journal of exactly the intact records' bytes.
TEST(KeyframeJournal, EachKindOfDamageLosesOnlyTheRecordsItIsIn) {
  for (const Damage& d : damages()) {
    SCOPED_TRACE(d.name);
    kestrel::test::TempDir dir;
    const Written w = write_journal(dir.path());
    d.apply(w);
    const std::string damaged = kestrel::test::read_file(w.path);
    const JournalContents c = read_journal(w.path);
    EXPECT_EQ(summary(c), d.records) << "read on after the damage";
    EXPECT_EQ(c.damage.rfind(d.damage_starts, 0), 0u) << c.damage;
    EXPECT_EQ(c.damaged_stretches, 1);
    const std::string fresh = fresh_journal_of(w, d.records);
    const uint64_t intact = fresh.size() - (d.header_damaged ? w.ends[0] : 0);
    EXPECT_EQ(c.file_bytes, damaged.size());
    EXPECT_EQ(c.intact_bytes, intact);
    EXPECT_EQ(c.skipped_bytes, damaged.size() - intact) << "every byte is intact or skipped, once";
    expect_kept_and_continued(w, damaged, d.keyframes, fresh, d.records);
  }
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

// Pruning by hand-made names: kept journals are ordered by the time (then the number) in their
// names, not as text; the one just set aside always stays, even when its name is older (a wall
// clock stepped back); names keep_aside() does not give, other kinds and other journals, a
// folder and a symbolic link are never touched.
TEST(KeyframeJournal, PruningKeepsTheNewestJournalsSetAsideOfOneKindAndNothingElse) {
  kestrel::test::TempDir dir;
  const std::string journal = (dir / "mapper.journal").string();
  const auto make = [&](const std::string& name) { std::ofstream(dir / name) << name; };
  for (const char* name : {"mapper.journal", "mapper.journal.reset-900", "mapper.journal.reset-1000",
                           "mapper.journal.reset-2000", "mapper.journal.reset-2000-2", "mapper.journal.reset-3000",
                           "mapper.journal.damaged-100", "mapper.journal.reset-abc", "mapper.journal.reset-1500-1",
                           "mapper.journal.reset-", "mapper.journal.reset-1-2-3", "other.journal.reset-10",
                           "mapper.journal.reset-700.tmp"})
    make(name);
  fs::create_directory(dir / "mapper.journal.reset-10");
  fs::create_symlink(dir / "mapper.journal.reset-900", dir / "mapper.journal.reset-20");
  const auto in_dir = [&](const std::vector<std::string>& names) {
    std::vector<std::string> paths;
    for (const std::string& name : names) paths.push_back((dir / name).string());
    return paths;
  };
  EXPECT_EQ(kept_journals(journal, "reset"),
            in_dir({"mapper.journal.reset-900", "mapper.journal.reset-1000", "mapper.journal.reset-2000",
                    "mapper.journal.reset-2000-2", "mapper.journal.reset-3000"}));

  // Keep 3, the newest just set aside: 900 and 1000 go, oldest first.
  PrunedJournals pruned = prune_kept_journals(journal, "reset", 3, (dir / "mapper.journal.reset-3000").string());
  EXPECT_EQ(pruned.removed, in_dir({"mapper.journal.reset-900", "mapper.journal.reset-1000"}));
  EXPECT_TRUE(pruned.failures.empty());
  EXPECT_EQ(kept_journals(journal, "reset"),
            in_dir({"mapper.journal.reset-2000", "mapper.journal.reset-2000-2", "mapper.journal.reset-3000"}));

  // Keep 2, the one just set aside named older than all (the clock stepped back): it stays,
  // with the newest other; 2000 and 2000-2 go.
  make("mapper.journal.reset-50");
  pruned = prune_kept_journals(journal, "reset", 2, (dir / "mapper.journal.reset-50").string());
  EXPECT_EQ(pruned.removed, in_dir({"mapper.journal.reset-2000", "mapper.journal.reset-2000-2"}));
  EXPECT_EQ(kept_journals(journal, "reset"), in_dir({"mapper.journal.reset-50", "mapper.journal.reset-3000"}));

  // Nothing else was touched.
  for (const char* name : {"mapper.journal", "mapper.journal.damaged-100", "mapper.journal.reset-abc",
                           "mapper.journal.reset-1500-1", "mapper.journal.reset-", "mapper.journal.reset-1-2-3",
                           "other.journal.reset-10", "mapper.journal.reset-700.tmp"})
    EXPECT_EQ(kestrel::test::read_file(dir / name), name) << name;
  EXPECT_TRUE(fs::is_directory(dir / "mapper.journal.reset-10"));
  EXPECT_TRUE(fs::is_symlink(dir / "mapper.journal.reset-20"));
  // Keeping none would delete what was just set aside: refused.
  EXPECT_THROW(prune_kept_journals(journal, "reset", 0, ""), std::invalid_argument);
}

// A writer prunes as it sets journals aside: each RESET and each damaged journal continued
// leaves at most `keep` of its kind, the journal just set aside among them, and says which it
// deleted.
TEST(KeyframeJournal, AWriterKeepsOnlyTheNewestJournalsSetAsideOfEachKind) {
  kestrel::test::TempDir dir;
  const std::string path = (dir / "mapper.journal").string();
  const auto graph = [](int64_t revision) {
    kestrel::slam_graph_t g{};
    g.revision = revision;
    return g;
  };
  std::vector<std::string> resets;
  {
    JournalWriter writer(path, {}, 2);
    for (int64_t round = 0; round < 3; ++round) {
      writer.graph(graph(round));
      writer.restart();
      resets.push_back(writer.kept_aside());
      EXPECT_EQ(writer.pruned().removed, round < 2 ? std::vector<std::string>{} : std::vector<std::string>{resets[0]})
          << "round " << round;
    }
  }
  EXPECT_FALSE(fs::exists(resets[0]));
  EXPECT_EQ(kept_journals(path, "reset"), (std::vector<std::string>{resets[1], resets[2]}));
  EXPECT_EQ(read_journal(resets[2]).records.at(0).graph.revision, 2) << "the newest kept is the last one ended";

  // Damaged twice with keep 1: the second continuation deletes the first damaged file only.
  std::vector<std::string> damaged;
  for (int64_t round = 0; round < 2; ++round) {
    {
      JournalWriter writer(path, read_journal(path), 1);
      writer.graph(graph(10 + round));
    }
    fs::resize_file(path, fs::file_size(path) - 1);  // the record just written cut short
    JournalWriter writer(path, read_journal(path), 1);
    damaged.push_back(writer.kept_aside());
    ASSERT_NE(damaged.back(), "");
    EXPECT_EQ(writer.pruned().removed, round == 0 ? std::vector<std::string>{} : std::vector<std::string>{damaged[0]});
  }
  EXPECT_EQ(kept_journals(path, "damaged"), std::vector<std::string>{damaged[1]});
  EXPECT_EQ(kept_journals(path, "reset"), (std::vector<std::string>{resets[1], resets[2]})) << "another kind";
  EXPECT_THROW(JournalWriter(path, read_journal(path), 0), std::invalid_argument);
}

// Compaction replaces the file by one rename: keyframes as their last records placed them
// (keyframe 0 where the graph moved it), a graph record of the revision, and appends go on in
// the new file. Asked for a keyframe the journal never held, it changes nothing and the old
// file is still appended to.
TEST(KeyframeJournal, CompactionKeepsTheKeyframesAsPlacedOrChangesNothing) {
  kestrel::test::TempDir dir;
  const Written w = write_journal(dir.path());
  const JournalContents read = read_journal(w.path);
  const auto frame_of = [&](int64_t id) {
    for (const JournalRecord& r : read.records)
      if (r.kind == JournalRecord::Kind::kKeyframe && r.keyframe.id == id) return &r.frame;
    return static_cast<const RgbdFrame*>(nullptr);
  };
  JournalWriter writer(w.path, read);
  EXPECT_THROW(writer.compact({{0, frame_of(0)}, {7, frame_of(1)}}, 2), std::invalid_argument);
  EXPECT_TRUE(kestrel::test::read_file(w.path) == w.bytes) << "nothing changed";
  kestrel::slam_graph_t later{};
  later.revision = 3;
  writer.graph(later);
  EXPECT_EQ(summary(read_journal(w.path)), "K0 K1 G K2 K3 G");

  writer.compact({{0, frame_of(0)}, {2, frame_of(2)}, {3, frame_of(3)}}, 3);
  EXPECT_EQ(writer.compactions(), 1);
  const JournalContents compacted = read_journal(w.path);
  EXPECT_EQ(compacted.damage, "");
  EXPECT_EQ(summary(compacted), "K0 K2 K3 G");
  EXPECT_EQ(writer.bytes(), compacted.file_bytes);
  const auto& moved = compacted.records[0].keyframe.T_world_camera;
  const auto expected = keyframe(0, 100000, 0.05).T_world_camera;  // as the graph record moved it
  EXPECT_EQ(std::vector<double>(moved.position, moved.position + 3),
            std::vector<double>(expected.position, expected.position + 3));
  EXPECT_EQ(compacted.records.back().graph.revision, 3);
  EXPECT_EQ(compacted.records.back().graph.keyframes.size(), 0u);
  writer.graph(later);
  EXPECT_EQ(summary(read_journal(w.path)), "K0 K2 K3 G G");
  EXPECT_TRUE(kept_journals(w.path, "reset").empty() && kept_journals(w.path, "damaged").empty());
}

// Frames pinned for keyframes SLAM has not placed yet (version 2's 'P' records): read past
// damage like the other kinds, written by a compaction, and pinned again by a restore unless a
// later keyframe record of the same time shows that their keyframe joined. A version 1 journal
// (no such records) still reads whole.
TEST(KeyframeJournal, PinnedFramesAreJournaledAndPinnedAgainUnlessTheirKeyframeJoined) {
  kestrel::test::TempDir dir;
  const test::Scene scene = test::room_with_a_box();
  const Written w = write_journal(dir.path());
  const auto frame_at = [&](int64_t utime) {
    return decimate(scene.render(test::kinect_camera(160, 120), test::look_at({-0.5, 0.0, 1.2}, {2.0, 0.3, 0.7}), utime), 5);
  };
  {
    JournalWriter writer(w.path, read_journal(w.path));
    writer.pinned(frame_at(500000));
    writer.pinned(frame_at(600000));
    writer.pinned(frame_at(700000));
    writer.pinned(frame_at(800000));
    writer.keyframe(keyframe(6, 700000, 0.6), frame_at(700000));  // 7's keyframe joined
    writer.released({800000});                                     // 8's was let go
  }
  const JournalContents read = read_journal(w.path);
  ASSERT_EQ(read.damage, "");
  EXPECT_EQ(read.version, 2);
  EXPECT_EQ(summary(read), "K0 K1 G K2 K3 P5 P6 P7 P8 K6 R");
  MapperOptions options;
  options.max_pinned_frames = 1;
  Mapper bounded(options);
  EXPECT_EQ(restore_journal(read, bounded, w.path).pinned, 1);
  EXPECT_EQ(bounded.pinned_frames().front()->utime, 600000) << "the newest kept within the bound";
  Mapper mapper;
  const Restored restored = restore_journal(read, mapper, w.path);
  EXPECT_EQ(restored.keyframes, 5);
  EXPECT_EQ(restored.pinned, 2);
  ASSERT_EQ(mapper.pinned(), 2u);
  EXPECT_NE(mapper.buffered(500000), nullptr);
  EXPECT_NE(mapper.buffered(600000), nullptr);
  EXPECT_EQ(mapper.buffered(700000), nullptr) << "its keyframe joined before the restart";
  EXPECT_EQ(mapper.buffered(800000), nullptr) << "let go before the restart";

  // A flipped byte in the first pinned record loses it alone: reading finds the next one.
  const std::string whole = kestrel::test::read_file(w.path);
  const size_t first_pin = w.ends.back() + 100;
  std::string damaged = whole;
  damaged[first_pin] = static_cast<char>(damaged[first_pin] ^ 0x5a);
  kestrel::test::TempDir dir2;
  const std::string damaged_path = (dir2.path() / "mapper.journal").string();
  const auto write_file = [](const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  };
  write_file(damaged_path, damaged);
  EXPECT_EQ(summary(read_journal(damaged_path)), "K0 K1 G K2 K3 P6 P7 P8 K6 R");

  // A compaction writes the pins it is given, after the keyframes and the graph.
  {
    JournalWriter writer(w.path, read);
    const RgbdFrame pin = frame_at(500000);
    writer.compact({{0, &read.records[0].frame}}, 2, {&pin});
  }
  EXPECT_EQ(summary(read_journal(w.path)), "K0 G P5");

  // Version 1: the records before the pins, under the old header. It reads whole, and a
  // writer continues it as version 2 (the same records under the new header) before appending.
  std::string version1 = whole.substr(0, w.ends.back());
  version1.replace(0, version1.find('\n'), "kestrel mapper journal 1");
  write_file(damaged_path, version1);
  const JournalContents old = read_journal(damaged_path);
  EXPECT_EQ(old.damage, "");
  EXPECT_EQ(old.version, 1);
  EXPECT_EQ(summary(old), "K0 K1 G K2 K3");
  {
    JournalWriter writer(damaged_path, old);
    writer.pinned(frame_at(500000));
  }
  const std::string continued = kestrel::test::read_file(damaged_path);
  EXPECT_EQ(continued.substr(0, w.ends.back()), whole.substr(0, w.ends.back())) << "the same bytes under the version 2 header";
  const JournalContents upgraded = read_journal(damaged_path);
  EXPECT_EQ(upgraded.version, 2);
  EXPECT_EQ(upgraded.damage, "");
  EXPECT_EQ(summary(upgraded), "K0 K1 G K2 K3 P5");
  EXPECT_TRUE(kept_journals(damaged_path, "damaged").empty());
}

}  // namespace
}  // namespace kestrel::mapper
