#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/transport/log_file.h"
#include "kestrel/imu_t.hpp"
#include "test/support/test_support.h"

namespace kestrel::transport {
namespace {

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const std::filesystem::path& p, const std::vector<uint8_t>& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()),
                                           static_cast<std::streamsize>(b.size()));
}

// Ten IMU events, 100 bytes of payload each plus a 28-byte header and a 3-byte channel.
void write_log(const std::filesystem::path& p) {
  LogWriter w(p);
  for (int i = 0; i < 10; ++i) {
    kestrel::imu_t m{};
    m.utime = 1000 + i;
    m.seq = i;
    w.write_message("IMU", m.utime, m);
  }
  w.close();
}

std::vector<int64_t> read_seqs(LogReader& r) {
  std::vector<int64_t> seqs;
  while (auto e = r.next()) {
    seqs.push_back(decode_message<kestrel::imu_t>(e->data.data(), e->data.size(), e->channel).seq);
  }
  return seqs;
}

TEST(LogFile, WriteThenReadBack) {
  test::TempDir dir;
  write_log(dir / "a.lcmlog");
  LogReader r(dir / "a.lcmlog");
  const auto seqs = read_seqs(r);
  ASSERT_EQ(seqs.size(), 10u);
  EXPECT_EQ(seqs.front(), 0);
  EXPECT_EQ(seqs.back(), 9);
  EXPECT_EQ(r.damage_report(), "");
}

TEST(LogFile, ReadMessagesKeepsOneChannelInOrder) {
  test::TempDir dir;
  const std::string path = (dir / "two.lcmlog").string();
  LogWriter w(path);
  for (int i = 0; i < 6; ++i) {
    kestrel::imu_t m{};
    m.utime = 1000 + i;
    m.seq = i;
    w.write_message(i % 2 == 0 ? "IMU" : "OTHER", m.utime, m);
  }
  w.close();
  const auto imu = read_messages<kestrel::imu_t>(path, "IMU");
  ASSERT_EQ(imu.size(), 3u);
  EXPECT_EQ(imu[0].seq, 0);
  EXPECT_EQ(imu[1].seq, 2);
  EXPECT_EQ(imu[2].seq, 4);
  EXPECT_TRUE(read_messages<kestrel::imu_t>(path, "NONE").empty());
}

TEST(LogFile, TruncatedTailIsReportedNotFatal) {
  test::TempDir dir;
  write_log(dir / "a.lcmlog");
  auto bytes = read_bytes(dir / "a.lcmlog");
  bytes.resize(bytes.size() - 10);
  write_bytes(dir / "t.lcmlog", bytes);
  LogReader r(dir / "t.lcmlog");
  EXPECT_EQ(read_seqs(r).size(), 9u);
  EXPECT_TRUE(r.truncated());
  EXPECT_NE(r.damage_report().find("t.lcmlog: damaged LCM log: truncated last event"), std::string::npos)
      << r.damage_report();
}

TEST(LogFile, CorruptEventIsSkippedAndTheRestRead) {
  test::TempDir dir;
  write_log(dir / "a.lcmlog");
  auto bytes = read_bytes(dir / "a.lcmlog");
  const size_t event_size = bytes.size() / 10;
  // Damage the sync word of event 3 and the length field of event 6.
  bytes[3 * event_size] ^= 0xff;
  bytes[6 * event_size + 24] = 0x7f;
  write_bytes(dir / "c.lcmlog", bytes);
  LogReader r(dir / "c.lcmlog");
  const auto seqs = read_seqs(r);
  EXPECT_EQ(seqs, (std::vector<int64_t>{0, 1, 2, 4, 5, 7, 8, 9}));
  EXPECT_EQ(r.corrupt_regions(), 2);
  EXPECT_FALSE(r.truncated());
  EXPECT_EQ(r.skipped_bytes(), static_cast<int64_t>(2 * event_size));
}

TEST(LogFile, RewindReadsTheSameEventsAgainAndCountsTheDamageOnce) {
  test::TempDir dir;
  write_log(dir / "a.lcmlog");
  auto bytes = read_bytes(dir / "a.lcmlog");
  bytes[3 * (bytes.size() / 10)] ^= 0xff;  // event 3's sync word
  bytes.resize(bytes.size() - 10);         // and a truncated tail
  write_bytes(dir / "d.lcmlog", bytes);
  LogReader r(dir / "d.lcmlog");
  ASSERT_TRUE(r.next().has_value());
  r.rewind();  // mid-file
  const auto first = read_seqs(r);
  const std::string damage = r.damage_report();
  r.rewind();  // at the end
  EXPECT_EQ(read_seqs(r), first);
  EXPECT_EQ(first, (std::vector<int64_t>{0, 1, 2, 4, 5, 6, 7, 8}));
  EXPECT_EQ(r.corrupt_regions(), 1);
  EXPECT_TRUE(r.truncated());
  EXPECT_EQ(r.damage_report(), damage);
}

TEST(LogFile, ASeekToAnEventsOffsetReadsItAgainAndDamageIsCountedOnce) {
  test::TempDir dir;
  write_log(dir / "a.lcmlog");
  auto bytes = read_bytes(dir / "a.lcmlog");
  bytes[3 * (bytes.size() / 10)] ^= 0xff;  // event 3's sync word
  write_bytes(dir / "d.lcmlog", bytes);
  LogReader r(dir / "d.lcmlog");
  std::vector<int64_t> offsets;
  while (auto e = r.next()) offsets.push_back(e->offset);
  ASSERT_EQ(offsets.size(), 9u);
  EXPECT_EQ(offsets.front(), 0);
  const std::string damage = r.damage_report();
  // Back over the damage, to event 2 (the third read), then to the last.
  r.seek(offsets[2]);
  EXPECT_EQ(read_seqs(r), (std::vector<int64_t>{2, 4, 5, 6, 7, 8, 9}));
  r.seek(offsets.back());
  EXPECT_EQ(read_seqs(r), (std::vector<int64_t>{9}));
  EXPECT_EQ(r.corrupt_regions(), 1);
  EXPECT_EQ(r.damage_report(), damage);
  // Past the damage unread, then back over it: counted once all the same.
  LogReader skipping(dir / "d.lcmlog");
  skipping.seek(offsets[5]);
  EXPECT_EQ(read_seqs(skipping), (std::vector<int64_t>{6, 7, 8, 9}));
  EXPECT_EQ(skipping.corrupt_regions(), 0);
  skipping.rewind();
  EXPECT_EQ(read_seqs(skipping), (std::vector<int64_t>{0, 1, 2, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(skipping.damage_report(), damage);
  EXPECT_THROW(r.seek(-1), std::out_of_range);
  EXPECT_THROW(r.seek(static_cast<int64_t>(bytes.size()) + 1), std::out_of_range);
}

TEST(LogFile, NotALogAndMissingFileAreInputErrors) {
  test::TempDir dir;
  write_bytes(dir / "junk.lcmlog", std::vector<uint8_t>(100, 0x42));
  EXPECT_THROW(LogReader(dir / "junk.lcmlog"), InputError);
  EXPECT_THROW(LogReader(dir / "missing.lcmlog"), InputError);
  write_bytes(dir / "empty.lcmlog", {});
  LogReader empty(dir / "empty.lcmlog");
  EXPECT_FALSE(empty.next().has_value());
}

}  // namespace
}  // namespace kestrel::transport
