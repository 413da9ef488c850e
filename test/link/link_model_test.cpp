// The link emulator's model (tools/link/link_model.h) on hand-computed cases, and the LCM
// datagram router (tools/link/lcm_datagram.h) on datagrams built here byte by byte.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/link/lcm_datagram.h"
#include "tools/link/link_model.h"

namespace kestrel::link {
namespace {

LinkParams ideal(double rate_bps, int64_t queue_bytes) {
  LinkParams p;
  p.delay_s = 0.0;
  p.jitter_s = 0.0;
  p.loss = 0.0;
  p.rate_bps = rate_bps;
  p.queue_bytes = queue_bytes;
  return p;
}

TEST(LinkModel, A20MbitLinkDeliversAMegabyteBurstIn0_4Seconds) {
  LinkModel link(ideal(20e6, 2'000'000));
  // 1 MB as 1000 datagrams of 1000 bytes, all at t = 0: 8e6 bits at 20e6 bit/s.
  double last = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const Verdict v = link.offer(0.0, 1000);
    ASSERT_EQ(v.fate, Verdict::kDelivered) << i;
    EXPECT_NEAR(v.deliver_at, (i + 1) * 8000.0 / 20e6, 1e-12) << i;
    last = v.deliver_at;
  }
  EXPECT_NEAR(last, 0.4, 1e-9);
  EXPECT_EQ(link.stats().delivered, 1000);
  EXPECT_EQ(link.stats().bytes_delivered, 1'000'000);
}

TEST(LinkModel, AnIdleLinkAddsOnlyTransmissionAndDelay) {
  LinkParams p = ideal(8e6, 100'000);  // 1 byte per microsecond
  p.delay_s = 0.030;
  LinkModel link(p);
  EXPECT_NEAR(link.offer(1.0, 1000).deliver_at, 1.0 + 0.001 + 0.030, 1e-12);
  // Long after: the link is idle again.
  EXPECT_NEAR(link.offer(2.0, 500).deliver_at, 2.0 + 0.0005 + 0.030, 1e-12);
}

TEST(LinkModel, AFullQueueDropsTheTailAndTakesItAgainOnceDrained) {
  LinkModel link(ideal(8e6, 3000));  // 1 byte per microsecond, 3000 bytes of queue
  EXPECT_EQ(link.offer(0.0, 1000).fate, Verdict::kDelivered);
  EXPECT_EQ(link.offer(0.0, 1000).fate, Verdict::kDelivered);
  EXPECT_EQ(link.offer(0.0, 1000).fate, Verdict::kDelivered);   // backlog 2000 + 1000 = 3000: fits
  EXPECT_EQ(link.offer(0.0, 1).fate, Verdict::kQueueFull);      // 3001
  EXPECT_NEAR(link.backlog_bytes(0.0), 3000.0, 1e-9);
  // 1.5 ms later 1500 bytes have left: 1500 + 1000 fits, then 2500 + 1000 does not.
  const Verdict v = link.offer(0.0015, 1000);
  EXPECT_EQ(v.fate, Verdict::kDelivered);
  EXPECT_NEAR(v.deliver_at, 0.004, 1e-12);  // behind the first 3000 bytes
  EXPECT_EQ(link.offer(0.0015, 1000).fate, Verdict::kQueueFull);
  EXPECT_EQ(link.stats().queue_full, 2);
  EXPECT_LE(link.stats().max_backlog_bytes, 3000.0);
  // A datagram bigger than the whole queue never fits.
  EXPECT_EQ(link.offer(10.0, 3001).fate, Verdict::kQueueFull);
}

TEST(LinkModel, TheLossFractionIsWithinBinomialBoundsAndTheSeedRepeatsIt) {
  LinkParams p = ideal(1e9, 1'000'000);
  p.loss = 0.10;
  p.seed = 7;
  const int n = 20000;
  LinkModel a(p), b(p);
  int lost = 0;
  for (int i = 0; i < n; ++i) {
    const Verdict va = a.offer(i * 1e-3, 100);
    const Verdict vb = b.offer(i * 1e-3, 100);
    ASSERT_EQ(va.fate, vb.fate) << i;
    lost += va.fate == Verdict::kLost;
  }
  // Binomial(20000, 0.1): mean 2000, sd sqrt(1800) = 42.4; +-5 sd.
  EXPECT_NEAR(lost, 2000, 5 * std::sqrt(n * 0.1 * 0.9));
  EXPECT_EQ(a.stats().lost, lost);
  p.seed = 8;
  LinkModel c(p);
  int lost_c = 0;
  for (int i = 0; i < n; ++i) lost_c += c.offer(i * 1e-3, 100).fate == Verdict::kLost;
  EXPECT_NE(lost_c, lost) << "another seed, another draw";
}

TEST(LinkModel, JitterStaysWithinItsBoundsAndSpreadsOverThem) {
  LinkParams p = ideal(1e9, 1'000'000);
  p.delay_s = 0.030;
  p.jitter_s = 0.010;
  LinkModel link(p);
  double lo = 1.0, hi = 0.0, sum = 0.0;
  const int n = 5000;
  for (int i = 0; i < n; ++i) {
    const double t = i * 0.1;  // sparse: never behind the previous delivery
    const Verdict v = link.offer(t, 125);  // 1 microsecond at 1 Gbit/s
    ASSERT_EQ(v.fate, Verdict::kDelivered);
    const double d = v.deliver_at - t - 1e-6;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
    sum += d;
  }
  EXPECT_GE(lo, 0.020 - 1e-12);
  EXPECT_LE(hi, 0.040 + 1e-12);
  EXPECT_LT(lo, 0.0205);  // uniform over the whole range
  EXPECT_GT(hi, 0.0395);
  EXPECT_NEAR(sum / n, 0.030, 0.0005);
}

TEST(LinkModel, DeliveriesKeepTheirOrderUnderJitter) {
  LinkParams p = ideal(1e9, 1'000'000);
  p.delay_s = 0.030;
  p.jitter_s = 0.010;
  LinkModel link(p);
  double previous = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const Verdict v = link.offer(i * 1e-4, 100);  // closer than the jitter's spread
    ASSERT_GE(v.deliver_at, previous) << i;
    ASSERT_GE(v.deliver_at, i * 1e-4 + 0.020) << i;
    previous = v.deliver_at;
  }
}

TEST(LinkModel, LossTakesLinkTimeAndDoesNotShiftTheJitter) {
  LinkParams p = ideal(8e6, 1'000'000);
  p.loss = 1.0;
  LinkModel lossy(p);
  EXPECT_EQ(lossy.offer(0.0, 1000).fate, Verdict::kLost);
  EXPECT_NEAR(lossy.backlog_bytes(0.0), 1000.0, 1e-9);  // it was still sent
}

TEST(LinkModel, RefusesUnusableParameters) {
  LinkParams p;
  p.jitter_s = 0.05;  // more than the 30 ms delay
  EXPECT_THROW(LinkModel{p}, std::invalid_argument);
  p = LinkParams{};
  p.loss = 1.5;
  EXPECT_FALSE(check(p).empty());
  p = LinkParams{};
  p.rate_bps = 0;
  EXPECT_FALSE(check(p).empty());
  p = LinkParams{};
  p.queue_bytes = 0;
  EXPECT_FALSE(check(p).empty());
  EXPECT_TRUE(check(LinkParams{}).empty());
}

// ---- LCM datagrams ----

void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(v >> s));
}
void put16(std::vector<uint8_t>& b, uint16_t v) {
  b.push_back(static_cast<uint8_t>(v >> 8));
  b.push_back(static_cast<uint8_t>(v));
}

std::vector<uint8_t> short_datagram(uint32_t seqno, const std::string& channel, const std::string& payload) {
  std::vector<uint8_t> b;
  put32(b, 0x4c433032);
  put32(b, seqno);
  b.insert(b.end(), channel.begin(), channel.end());
  b.push_back(0);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

std::vector<uint8_t> fragment(uint32_t seqno, uint32_t size, uint32_t offset, uint16_t no, uint16_t count,
                              const std::string& channel, const std::string& payload) {
  std::vector<uint8_t> b;
  put32(b, 0x4c433033);
  put32(b, seqno);
  put32(b, size);
  put32(b, offset);
  put16(b, no);
  put16(b, count);
  if (no == 0) {
    b.insert(b.end(), channel.begin(), channel.end());
    b.push_back(0);
  }
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

TEST(LcmDatagram, ParsesShortAndFragmentedHeaders) {
  const auto s = short_datagram(5, "STATE", "abc");
  const auto h = parse_datagram(s.data(), s.size());
  ASSERT_TRUE(h);
  EXPECT_FALSE(h->fragmented);
  EXPECT_EQ(h->seqno, 5u);
  EXPECT_EQ(h->channel, "STATE");
  const auto f0 = fragment(9, 6, 0, 0, 2, "CAMERA_RGBD", "abc");
  const auto f1 = fragment(9, 6, 3, 1, 2, "", "def");
  const auto h0 = parse_datagram(f0.data(), f0.size());
  const auto h1 = parse_datagram(f1.data(), f1.size());
  ASSERT_TRUE(h0 && h1);
  EXPECT_TRUE(h0->fragmented);
  EXPECT_EQ(h0->channel, "CAMERA_RGBD");
  EXPECT_EQ(h1->fragment_no, 1);
  EXPECT_EQ(h1->fragments, 2);
  EXPECT_TRUE(h1->channel.empty());
}

TEST(LcmDatagram, RefusesWhatIsNotAnLcmDatagram) {
  const std::vector<uint8_t> junk = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_FALSE(parse_datagram(junk.data(), junk.size()));
  auto s = short_datagram(1, "STATE", "");
  s.pop_back();  // the NUL
  EXPECT_FALSE(parse_datagram(s.data(), s.size()));
  const auto long_name = short_datagram(1, std::string(64, 'A'), "x");
  EXPECT_FALSE(parse_datagram(long_name.data(), long_name.size()));
  const auto bad_fragment = fragment(1, 6, 0, 2, 2, "", "abc");  // number 2 of 2
  EXPECT_FALSE(parse_datagram(bad_fragment.data(), bad_fragment.size()));
}

TEST(Router, ForwardsOnlyItsChannelsAndRenames) {
  Router r({"STATE", "CAMERA_RGBD_Z>CAMERA_RGBD"});
  const auto state = short_datagram(1, "STATE", "xyz");
  const auto out = r.route(1, state.data(), state.size());
  ASSERT_TRUE(out);
  EXPECT_EQ(*out, state);
  const auto imu = short_datagram(2, "IMU", "xyz");
  EXPECT_FALSE(r.route(1, imu.data(), imu.size()));
  const auto z = short_datagram(3, "CAMERA_RGBD_Z", "payload");
  const auto renamed = r.route(1, z.data(), z.size());
  ASSERT_TRUE(renamed);
  EXPECT_EQ(*renamed, short_datagram(3, "CAMERA_RGBD", "payload"));
  EXPECT_EQ(r.far_name("CAMERA_RGBD_Z"), "CAMERA_RGBD");
  EXPECT_EQ(r.far_name("IMU"), "");
}

TEST(Router, FollowsAFragmentedMessageBySenderAndSequenceNumber) {
  Router r({"CAMERA_RGBD_Z>CAMERA_RGBD"});
  // Sender 1's frame and sender 2's IMU-sized fragmented message interleaved.
  const auto a0 = fragment(7, 6, 0, 0, 2, "CAMERA_RGBD_Z", "abc");
  const auto b0 = fragment(7, 6, 0, 0, 2, "SLAM_GRAPH", "uvw");
  const auto a1 = fragment(7, 6, 3, 1, 2, "", "def");
  const auto b1 = fragment(7, 6, 3, 1, 2, "", "xyz");
  const auto o0 = r.route(1, a0.data(), a0.size());
  EXPECT_FALSE(r.route(2, b0.data(), b0.size()));
  const auto o1 = r.route(1, a1.data(), a1.size());
  EXPECT_FALSE(r.route(2, b1.data(), b1.size()));
  ASSERT_TRUE(o0 && o1);
  EXPECT_EQ(*o0, fragment(7, 6, 0, 0, 2, "CAMERA_RGBD", "abc"));
  EXPECT_EQ(*o1, a1);  // no channel in it: unchanged
  EXPECT_EQ(r.forwarded().at("CAMERA_RGBD_Z"), 2);
  // A fragment whose fragment 0 was never seen does not cross.
  const auto stray = fragment(8, 6, 3, 1, 2, "", "def");
  EXPECT_FALSE(r.route(1, stray.data(), stray.size()));
  EXPECT_EQ(r.orphan_fragments(), 1);
  const std::vector<uint8_t> junk = {0, 1};
  EXPECT_FALSE(r.route(1, junk.data(), junk.size()));
  EXPECT_EQ(r.malformed(), 1);
}

TEST(Router, RefusesBadRules) {
  EXPECT_THROW(Router({""}), std::invalid_argument);
  EXPECT_THROW(Router({"A>"}), std::invalid_argument);
  EXPECT_THROW(Router({">B"}), std::invalid_argument);
  EXPECT_THROW(Router({"A", "A>B"}), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::link
