// The process adapter on LCM's in-process transport (memq://): decoding and rejection,
// heartbeats (and the health they report while input is rejected), and the lock-step
// acknowledgements the replay depends on.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

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

// Handles everything queued (memq delivers one message per handle), then lets the node send
// its heartbeat, and delivers that too. Spinning a fixed number of times is not enough with a
// heartbeat period of 0: each spin queues a heartbeat, so the queue would never empty.
void drain(Node& node) {
  for (int round = 0; round < 3; ++round) {
    while (node.lcm().handleTimeout(0) > 0) {
    }
    node.spin_once(0);
  }
  while (node.lcm().handleTimeout(0) > 0) {
  }
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


using Status = kestrel::process_status_t;

// A node on IMU and CAMERA whose handlers reject a negative utime, as a library would.
struct RejectingNode {
  Node node;
  Tap<Status> status;
  explicit RejectingNode(double heartbeat_period_s)
      : node("vo", "memq://", heartbeat_period_s), status(node.lcm(), channel::kProcessStatus) {
    for (const char* channel : {"IMU", "CAMERA"}) {
      const std::string name = channel;
      node.subscribe<kestrel::imu_t>(name, [name](const kestrel::imu_t& m) {
        if (m.utime < 0) throw InputError(name + ": utime " + std::to_string(m.utime) + " is negative");
      });
    }
  }
  const Status& last() {
    drain(node);
    EXPECT_FALSE(status.got.empty());
    return status.got.back();
  }
};

TEST(NodeHealth, RejectedInputIsDegradedWithTheReasonUntilInputIsAcceptedAgain) {
  RejectingNode n(0.0);
  n.node.set_health(Status::STATE_RUNNING, "tracking");
  n.node.publish("IMU", imu(1));
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);

  n.node.publish("IMU", imu(-3));
  EXPECT_EQ(n.last().state, Status::STATE_DEGRADED);
  EXPECT_EQ(n.last().message, "rejecting IMU: utime -3 is negative; tracking");
  // The process's own health, set meanwhile, is kept and not shown over the rejection.
  n.node.set_health(Status::STATE_RUNNING, "tracking again");
  EXPECT_EQ(n.last().state, Status::STATE_DEGRADED);
  EXPECT_EQ(n.last().message, "rejecting IMU: utime -3 is negative; tracking again");
  EXPECT_EQ(n.node.health().state, Status::STATE_DEGRADED);

  n.node.lcm().publish("IMU", "xyz", 3);  // undecodable: the reason follows the last rejection
  EXPECT_EQ(n.last().message.rfind("rejecting IMU: 3 bytes are too short", 0), 0u) << n.last().message;

  n.node.publish("IMU", imu(2));
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);
  EXPECT_EQ(n.last().message, "tracking again");
  EXPECT_EQ(n.node.counters().messages_rejected, 2);

  // A process that set itself DEGRADED stays so, with its own reason, after the rejection.
  n.node.set_health(Status::STATE_DEGRADED, "no map yet");
  n.node.publish("IMU", imu(-1));
  EXPECT_EQ(n.last().message, "rejecting IMU: utime -1 is negative; no map yet");
  n.node.publish("IMU", imu(3));
  EXPECT_EQ(n.last().state, Status::STATE_DEGRADED);
  EXPECT_EQ(n.last().message, "no map yet");
}

// Good messages on a busy channel do not hide a channel whose last message was rejected.
TEST(NodeHealth, EachRejectedChannelNeedsItsOwnGoodMessage) {
  RejectingNode n(0.0);
  n.node.set_health(Status::STATE_RUNNING, "");
  n.node.publish("CAMERA", imu(-5));
  for (int i = 0; i < 20; ++i) n.node.publish("IMU", imu(i));
  EXPECT_EQ(n.last().state, Status::STATE_DEGRADED);
  EXPECT_EQ(n.last().message, "rejecting CAMERA: utime -5 is negative");

  n.node.publish("IMU", imu(-7));  // the newer rejection is named, the other listed
  EXPECT_EQ(n.last().message, "rejecting IMU: utime -7 is negative (also rejecting CAMERA)");
  n.node.publish("IMU", imu(30));
  EXPECT_EQ(n.last().message, "rejecting CAMERA: utime -5 is negative");
  n.node.publish("CAMERA", imu(31));
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);
  EXPECT_EQ(n.last().message, "");
}

// One bad message among good ones shows at once and for one heartbeat period, so that the
// launcher, which sees one heartbeat a period, sees it; then the process is RUNNING again.
TEST(NodeHealth, AnIsolatedRejectionShowsForOneHeartbeatPeriod) {
  RejectingNode n(1.0);
  n.node.set_health(Status::STATE_RUNNING, "");
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);
  const size_t before = n.status.got.size();
  n.node.publish("CAMERA", imu(-1));
  n.node.publish("CAMERA", imu(1));
  n.node.publish("CAMERA", imu(2));
  const Status& degraded = n.last();
  EXPECT_GT(n.status.got.size(), before);  // published when the state changed, not a period later
  EXPECT_EQ(degraded.state, Status::STATE_DEGRADED);
  EXPECT_EQ(degraded.message, "rejecting CAMERA: utime -1 is negative");
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  n.node.publish("CAMERA", imu(3));
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);
  // No good message needed to recover once the channel had one: only the period passing.
  n.node.publish("CAMERA", imu(-2));
  n.node.publish("CAMERA", imu(4));
  EXPECT_EQ(n.last().state, Status::STATE_DEGRADED);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  EXPECT_EQ(n.last().state, Status::STATE_RUNNING);
}

TEST(NodeHealth, StartingIsDegradedByRejectionsButStoppingAndFailedAreKept) {
  RejectingNode n(0.0);
  EXPECT_EQ(n.node.health().state, Status::STATE_STARTING);
  n.node.publish("IMU", imu(-1));
  drain(n.node);
  EXPECT_EQ(n.node.health().state, Status::STATE_DEGRADED);
  n.node.set_health(Status::STATE_FAILED, "camera lost");
  EXPECT_EQ(n.last().state, Status::STATE_FAILED);
  EXPECT_EQ(n.last().message, "camera lost");
  n.node.publish("IMU", imu(-2));
  EXPECT_EQ(n.last().state, Status::STATE_FAILED);
  n.node.set_health(Status::STATE_STOPPING, "");
  EXPECT_EQ(n.node.health().state, Status::STATE_STOPPING);
}

// The reason reaches an operator's terminal: no raw bytes from a damaged message, bounded length.
TEST(NodeHealth, TheReasonIsPrintableAndBounded) {
  Node node("raw", "memq://", 0.0);
  node.subscribe<kestrel::imu_t>("IMU", [](const kestrel::imu_t&) {
    throw InputError("IMU: name '\x01\x1b[2J\xff' " + std::string(1000, 'z'));
  });
  node.publish("IMU", imu(1));
  drain(node);
  const Node::Health h = node.health();
  EXPECT_EQ(h.state, Status::STATE_DEGRADED);
  EXPECT_EQ(h.message.rfind("rejecting IMU: name '\\x01\\x1B[2J\\xFF' zzz", 0), 0u) << h.message;
  EXPECT_LE(h.message.size(), 240u);
  for (const char c : h.message) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << static_cast<int>(c);
}

}  // namespace
}  // namespace kestrel::transport
