// The process adapter on LCM's in-process transport (memq://): decoding and rejection,
// heartbeats, and the lock-step acknowledgements the replay depends on.

#include <gtest/gtest.h>

#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/replay_ack_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::transport {
namespace {

// Collects what the node publishes on a channel, decoded.
template <class Msg>
struct Tap {
  std::vector<Msg> got;
  Tap(lcm::LCM& lcm, const std::string& channel) {
    lcm.subscribeFunction(channel, &Tap::on, this);
  }
  static void on(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Tap* self) {
    self->got.push_back(decode_message<Msg>(rbuf->data, rbuf->data_size, channel));
  }
};

void drain(Node& node) {
  for (int i = 0; i < 50; ++i) node.spin_once(0);
}

kestrel::imu_t imu(int64_t utime) {
  kestrel::imu_t m{};
  m.utime = utime;
  return m;
}

TEST(Node, DeliversValidMessagesAndRejectsBadOnes) {
  Node node("test", "memq://");
  std::vector<int64_t> seen;
  node.subscribe<kestrel::imu_t>("IMU", [&](const kestrel::imu_t& m) {
    if (m.utime < 0) throw InputError("negative time");
    seen.push_back(m.utime);
  });
  node.publish("IMU", imu(5));
  node.publish("IMU", kestrel::vo_update_t{});  // wrong type on the channel
  const uint8_t garbage[3] = {1, 2, 3};
  node.lcm().publish("IMU", garbage, 3);  // truncated
  node.publish("IMU", imu(-1));           // fails validation in the handler
  node.publish("IMU", imu(6));
  drain(node);
  EXPECT_EQ(seen, (std::vector<int64_t>{5, 6}));
  EXPECT_EQ(node.counters().messages_in, 5);
  EXPECT_EQ(node.counters().messages_rejected, 3);
  EXPECT_EQ(node.counters().last_input_utime, 6);
}

TEST(Node, HeartbeatListsChannelsAndCounters) {
  Node node("hb", "memq://", 0.0);
  Tap<kestrel::process_status_t> status(node.lcm(), channel::kProcessStatus);
  node.subscribe<kestrel::imu_t>("IMU", [&](const kestrel::imu_t&) { node.publish("OUT", imu(1)); });
  node.publish("IMU", imu(1));
  drain(node);
  ASSERT_FALSE(status.got.empty());
  const auto& s = status.got.back();
  EXPECT_EQ(s.name, "hb");
  EXPECT_EQ(s.subscriptions, std::vector<std::string>{"IMU"});
  EXPECT_NE(std::find(s.publications.begin(), s.publications.end(), "OUT"), s.publications.end());
  EXPECT_EQ(s.messages_in, 1);
}

TEST(Node, LockstepAcknowledgesEveryInputWithItsOutputs) {
  Node node("chain", "memq://");
  Tap<kestrel::replay_ack_t> acks(node.lcm(), channel::kReplayAck);
  int resets = 0;
  node.on_reset([&] { ++resets; });
  node.subscribe<kestrel::imu_t>("IMU", [&](const kestrel::imu_t& m) {
    if (m.utime % 2 == 0) {
      node.publish("A", imu(m.utime));
      node.publish("B", imu(m.utime));
    }
  });

  node.publish("IMU", imu(1));  // before the session: no acknowledgement
  drain(node);
  EXPECT_TRUE(acks.got.empty());

  kestrel::replay_control_t begin{};
  begin.session = 77;
  begin.command = kestrel::replay_control_t::COMMAND_BEGIN;
  node.publish(channel::kReplayControl, begin);
  kestrel::replay_control_t reset = begin;
  reset.command = kestrel::replay_control_t::COMMAND_RESET;
  node.publish(channel::kReplayControl, reset);
  node.publish("IMU", imu(2));
  node.publish("IMU", imu(3));
  node.lcm().publish("IMU", "x", 1);  // rejected inputs are acknowledged too
  drain(node);

  ASSERT_EQ(acks.got.size(), 3u);
  EXPECT_EQ(resets, 1);
  EXPECT_EQ(acks.got[0].session, 77);
  EXPECT_EQ(acks.got[0].process, "chain");
  EXPECT_EQ(acks.got[0].channel, "IMU");
  EXPECT_EQ(acks.got[0].input_utime, 2);
  EXPECT_EQ(acks.got[0].output_channels, (std::vector<std::string>{"A", "B"}));
  EXPECT_TRUE(acks.got[1].output_channels.empty());
  EXPECT_EQ(acks.got[2].input_utime, 0);

  kestrel::replay_control_t end = begin;
  end.command = kestrel::replay_control_t::COMMAND_END;
  node.publish(channel::kReplayControl, end);
  node.publish("IMU", imu(4));
  drain(node);
  EXPECT_EQ(acks.got.size(), 3u);
}

}  // namespace
}  // namespace kestrel::transport
