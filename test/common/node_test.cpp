// The process adapter on LCM's in-process transport (memq://): decoding and rejection,
// channel names that are not exact names, heartbeats (and the health they report while input
// is rejected, on a clock the test moves by hand), and the lock-step acknowledgements the
// replay depends on.

#include <gtest/gtest.h>
#include <unistd.h>

#include <ostream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "common/text.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/rejection_counts_t.hpp"
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

// Every rejection counted by channel and kind of fault: the same fault with other numbers is
// one reason, and PROCESS_REJECTIONS carries the counts with the latest rejection in full.
TEST(Node, RejectionsAreCountedPerChannelAndReasonAndSentWithTheHeartbeat) {
  Node node("counts", "memq://", 0.0);
  Tap<kestrel::rejection_counts_t> counts(node.lcm(), channel::kProcessRejections);
  node.subscribe<kestrel::imu_t>("IMU", [&](const kestrel::imu_t& m) {
    if (m.utime < 0) throw InputError("accelerometer " + std::to_string(-m.utime) + ".5 m/s^2 beyond 160 m/s^2");
  });
  node.publish("IMU", imu(1));
  drain(node);
  EXPECT_TRUE(counts.got.empty()) << "nothing was refused: no PROCESS_REJECTIONS";
  node.publish("IMU", imu(-500));
  node.publish("IMU", imu(-1200));
  const uint8_t garbage[3] = {1, 2, 3};
  node.lcm().publish("IMU", garbage, 3);
  node.publish("IMU", imu(-700));
  drain(node);
  ASSERT_FALSE(counts.got.empty());
  const kestrel::rejection_counts_t& last = counts.got.back();
  EXPECT_EQ(last.name, "counts");
  EXPECT_EQ(last.pid, static_cast<int32_t>(::getpid()));
  EXPECT_EQ(last.rejected, 4);
  ASSERT_EQ(last.num_reasons, 2);
  ASSERT_EQ(last.reasons.size(), 2u);
  int64_t total = 0;
  for (const auto& r : last.reasons) {
    EXPECT_EQ(r.channel, "IMU");
    total += r.count;
    if (r.reason == "accelerometer # m/s^# beyond # m/s^#") {
      EXPECT_EQ(r.count, 3);
      EXPECT_EQ(r.last, "accelerometer 700.5 m/s^2 beyond 160 m/s^2");
    } else {
      EXPECT_EQ(r.count, 1) << r.reason;
      EXPECT_NE(r.reason.find("too short"), std::string::npos) << r.reason;
    }
  }
  EXPECT_EQ(total, 4);
  EXPECT_EQ(node.rejection_counts().size(), 2u);
}

// Beyond kMaxReasonsPerChannel kinds on one channel the rest are counted together: a stream of
// varied garbage cannot grow the message without bound.
TEST(Node, ReasonsBeyondTheCapAreCountedTogether) {
  Node node("cap", "memq://", 0.0);
  const std::vector<std::string> words = {"alpha", "bravo", "charlie", "delta", "echo", "foxtrot", "golf",
                                          "hotel", "india", "juliet", "kilo", "lima", "mike", "november",
                                          "oscar", "papa", "quebec", "romeo", "sierra", "tango"};
  node.subscribe<kestrel::imu_t>("IMU", [&](const kestrel::imu_t& m) {
    throw InputError("fault " + words[static_cast<size_t>(m.utime) % words.size()]);
  });
  for (size_t i = 0; i < words.size(); ++i) node.publish("IMU", imu(static_cast<int64_t>(i)));
  drain(node);
  const auto counts = node.rejection_counts();
  ASSERT_EQ(counts.size(), Node::kMaxReasonsPerChannel + 1);
  int64_t total = 0, other = 0;
  for (const auto& r : counts) {
    total += r.count;
    if (r.reason == "other reasons") other = r.count;
  }
  EXPECT_EQ(total, static_cast<int64_t>(words.size()));
  EXPECT_EQ(other, static_cast<int64_t>(words.size() - Node::kMaxReasonsPerChannel));
}

TEST(RejectionReasonClass, NumbersBecomeHashesAndWordsStay) {
  EXPECT_EQ(rejection_reason_class("accelerometer 512.25 m/s^2"), "accelerometer # m/s^#");
  EXPECT_EQ(rejection_reason_class("utime -3 is negative"), "utime # is negative");
  EXPECT_EQ(rejection_reason_class("gyro 1e300 rad/s, 1.5E-3 and +7"), "gyro # rad/s, # and #");
  EXPECT_EQ(rejection_reason_class("range .5 m."), "range # m.");
  EXPECT_EQ(rejection_reason_class("frame x2 of CAM3D"), "frame x2 of CAM3D");
  EXPECT_EQ(rejection_reason_class("offset 12 ms - late"), "offset # ms - late");
  EXPECT_EQ(rejection_reason_class("byte \\x1b"), "byte \\x1b");
  EXPECT_EQ(rejection_reason_class(""), "");
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

  // BEGIN is answered with "joined" (an acknowledgement of the control channel), then one
  // acknowledgement per input.
  ASSERT_EQ(acks.got.size(), 4u);
  EXPECT_EQ(resets, 1);
  EXPECT_EQ(acks.got[0].session, 77);
  EXPECT_EQ(acks.got[0].process, "chain");
  EXPECT_EQ(acks.got[0].channel, channel::kReplayControl);
  EXPECT_TRUE(acks.got[0].output_channels.empty());
  EXPECT_EQ(acks.got[1].session, 77);
  EXPECT_EQ(acks.got[1].process, "chain");
  EXPECT_EQ(acks.got[1].channel, "IMU");
  EXPECT_EQ(acks.got[1].input_utime, 2);
  EXPECT_EQ(acks.got[1].output_channels, (std::vector<std::string>{"A", "B"}));
  EXPECT_TRUE(acks.got[2].output_channels.empty());
  EXPECT_EQ(acks.got[3].input_utime, 0);

  kestrel::replay_control_t end = begin;
  end.command = kestrel::replay_control_t::COMMAND_END;
  node.publish(channel::kReplayControl, end);
  node.publish("IMU", imu(4));
  drain(node);
  EXPECT_EQ(acks.got.size(), 4u);
}

// A name LCM would take as a pattern, or cannot take at all, is a configuration error naming
// the channel and why; the node is as it was, and exact names (up to LCM's 63 characters) work.
TEST(Node, AChannelThatIsNotAnExactNameIsAConfigurationError) {
  struct BadName {
    std::string channel;
    std::string error_starts;
  };
  const std::string too_long(64, 'A');
  const std::vector<BadName> bad = {
      {"", "channel '': is empty"},
      {too_long, "channel '" + too_long + "': has 64 characters; LCM takes at most 63"},
      {"CAM[", "channel 'CAM[': contains '[', which LCM would take as part of a pattern"},
      {"IMU.*", "channel 'IMU.*': contains '.', which LCM would take as part of a pattern"},
      {"CAMERA RGBD", "channel 'CAMERA RGBD': contains a space"},
      {"IMU\x1b", "channel 'IMU\\x1B': contains the byte \\x1B"},
      {"KAMERA_\xc3\x9c", "channel 'KAMERA_\xc3\x9c': contains the byte \\xC3"},
  };
  Node node("names", "memq://", 0.0);
  Tap<kestrel::process_status_t> status(node.lcm(), channel::kProcessStatus);
  for (const BadName& b : bad) {
    SCOPED_TRACE("channel '" + escape_bytes(b.channel) + "'");
    try {
      node.subscribe<kestrel::imu_t>(b.channel, [](const kestrel::imu_t&) {});
      ADD_FAILURE() << "subscribed";
    } catch (const CLI::ValidationError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(b.error_starts, 0), 0u) << e.what();
    }
  }
  const std::vector<std::string> good = {std::string(63, 'A'), "CAMERA_RGBD_Z", "robot1/IMU", "sim-imu:2"};
  std::vector<std::string> delivered;
  for (const std::string& channel : good) {
    node.subscribe<kestrel::imu_t>(channel,
                                   [&delivered, channel](const kestrel::imu_t&) { delivered.push_back(channel); });
    node.publish(channel, imu(1));
  }
  drain(node);
  EXPECT_EQ(delivered, good);
  ASSERT_FALSE(status.got.empty());
  EXPECT_EQ(status.got.back().subscriptions, good) << "no trace of the refused names";
}

// The error reaches a tool's main as a usage error: exit code 2, not a crash deep in LCM.
TEST(Node, ABadChannelEndsAToolWithTheUsageExitCode) {
  cli::App app("node-test", "subscribes to a channel that is a pattern");
  std::string tool = "kestrel-node-test";
  char* argv[] = {tool.data(), nullptr};
  const int code = app.run(1, argv, [] {
    Node node("t", "memq://");
    node.subscribe<kestrel::imu_t>("CAM[", [](const kestrel::imu_t&) {});
    return static_cast<int>(kExitOk);
  });
  EXPECT_EQ(code, kExitUsage);
}

TEST(Node, AnEmptyClockIsRefused) {
  EXPECT_THROW(Node("t", "memq://", 1.0, Node::Clock{}), std::invalid_argument);
}


using Status = kestrel::process_status_t;

// A clock the test moves by hand: the node's heartbeat period and rejection windows run on it,
// so a period passes when a step says so and never while a slow machine is busy.
struct ManualClock {
  int64_t now_us = 5'000'000;  // any origin: the node only takes differences
  Node::Clock function() {
    return [this] { return now_us; };
  }
};

// A node on IMU and CAMERA whose handlers reject a negative utime, as a library would.
struct RejectingNode {
  ManualClock clock;
  Node node;
  Tap<Status> status;
  explicit RejectingNode(double heartbeat_period_s)
      : node("vo", "memq://", heartbeat_period_s, clock.function()), status(node.lcm(), channel::kProcessStatus) {
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

// One thing that happens to a RejectingNode.
struct Action {
  enum class Kind { kImu, kBytes, kSetHealth, kAdvance };
  Kind kind = Kind::kAdvance;
  std::string text;   // kImu, kBytes: the channel; kSetHealth: the process's own reason
  int64_t value = 0;  // kImu: the first utime (negative: rejected); kSetHealth: the state; kAdvance: us
  int count = 1;      // kImu: this many imu_t messages, at utimes value, value + 1, ...
  std::string bytes;  // kBytes: published as they are (too short for imu_t: rejected)
};

Action imus_on(const std::string& channel, int64_t utime, int count = 1) {
  return {Action::Kind::kImu, channel, utime, count, ""};
}
Action bytes_on(const std::string& channel, const std::string& bytes) {
  return {Action::Kind::kBytes, channel, 0, 1, bytes};
}
Action set_own_health(int8_t state, const std::string& why) { return {Action::Kind::kSetHealth, why, state, 1, ""}; }
Action advance_us(int64_t us) { return {Action::Kind::kAdvance, "", us, 1, ""}; }

std::string describe(const Action& a) {
  switch (a.kind) {
    case Action::Kind::kImu:
      return std::to_string(a.count) + " message(s) on " + a.text + " from utime " + std::to_string(a.value);
    case Action::Kind::kBytes:
      return std::to_string(a.bytes.size()) + " raw bytes on " + a.text;
    case Action::Kind::kSetHealth:
      return "set_health(" + std::to_string(a.value) + ", \"" + a.text + "\")";
    case Action::Kind::kAdvance:
      break;
  }
  return "the clock advances " + std::to_string(a.value) + " us";
}

// A step of a health script: the action, then what the node must report, in its last heartbeat
// and in health() alike. A message ending in "..." is matched as a prefix.
struct Step {
  Action action;
  int8_t state;
  std::string message;
};

struct HealthScript {
  const char* name;
  double heartbeat_period_s;
  std::vector<Step> steps;
};
void PrintTo(const HealthScript& script, std::ostream* os) { *os << script.name; }

void expect_message(const std::string& got, const std::string& expected) {
  const std::string ellipsis = "...";
  const bool prefix = expected.size() >= ellipsis.size() &&
                      expected.compare(expected.size() - ellipsis.size(), ellipsis.size(), ellipsis) == 0;
  if (prefix) {
    const std::string start = expected.substr(0, expected.size() - ellipsis.size());
    EXPECT_EQ(got.rfind(start, 0), 0u) << got;
  } else {
    EXPECT_EQ(got, expected);
  }
}

std::vector<HealthScript> health_scripts() {
  const int8_t kRunning = Status::STATE_RUNNING, kDegraded = Status::STATE_DEGRADED;
  return {
      {"RejectedInputIsDegradedWithTheReasonUntilInputIsAcceptedAgain", 0.0,
       {
           {set_own_health(kRunning, "tracking"), kRunning, "tracking"},
           {imus_on("IMU", 1), kRunning, "tracking"},
           {imus_on("IMU", -3), kDegraded, "rejecting IMU: utime -3 is negative; tracking"},
           // The process's own health, set meanwhile, is kept and not shown over the rejection.
           {set_own_health(kRunning, "tracking again"), kDegraded,
            "rejecting IMU: utime -3 is negative; tracking again"},
           // Undecodable: the reason follows the last rejection.
           {bytes_on("IMU", "xyz"), kDegraded, "rejecting IMU: 3 bytes are too short..."},
           {imus_on("IMU", 2), kRunning, "tracking again"},
           // A process that set itself DEGRADED stays so, with its own reason, after the rejection.
           {set_own_health(kDegraded, "no map yet"), kDegraded, "no map yet"},
           {imus_on("IMU", -1), kDegraded, "rejecting IMU: utime -1 is negative; no map yet"},
           {imus_on("IMU", 3), kDegraded, "no map yet"},
       }},
      // Good messages on a busy channel do not hide a channel whose last message was rejected.
      // The clock stands still: the newer of two rejections in one tick is still the one named.
      {"EachRejectedChannelNeedsItsOwnGoodMessage", 0.0,
       {
           {set_own_health(kRunning, ""), kRunning, ""},
           {imus_on("CAMERA", -5), kDegraded, "rejecting CAMERA: utime -5 is negative"},
           {imus_on("IMU", 0, 20), kDegraded, "rejecting CAMERA: utime -5 is negative"},
           {imus_on("IMU", -7), kDegraded, "rejecting IMU: utime -7 is negative (also rejecting CAMERA)"},
           {imus_on("IMU", 30), kDegraded, "rejecting CAMERA: utime -5 is negative"},
           {imus_on("CAMERA", 31), kRunning, ""},
       }},
      // One bad message among good ones shows at once (the clock stands still, so the DEGRADED
      // heartbeat is the one sent on the change, not a periodic one) and for exactly one
      // heartbeat period, so that the launcher, which sees one heartbeat a period, sees it.
      {"AnIsolatedRejectionShowsForOneHeartbeatPeriod", 1.0,
       {
           {set_own_health(kRunning, ""), kRunning, ""},
           {imus_on("CAMERA", -1), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {imus_on("CAMERA", 1, 2), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {advance_us(999'999), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {advance_us(1), kRunning, ""},
           {imus_on("CAMERA", 3), kRunning, ""},
           // No good message needed to recover once the channel had one: only the period passing.
           {imus_on("CAMERA", -2), kDegraded, "rejecting CAMERA: utime -2 is negative"},
           {imus_on("CAMERA", 4), kDegraded, "rejecting CAMERA: utime -2 is negative"},
           {advance_us(1'100'000), kRunning, ""},
       }},
      // A sender whose last message was bad and that went quiet is not forgotten with time;
      // its next good message ends the rejection at once, the period being long over.
      {"ARejectedChannelStaysDegradedUntilAMessageOnItIsAccepted", 1.0,
       {
           {set_own_health(kRunning, ""), kRunning, ""},
           {imus_on("CAMERA", -1), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {advance_us(10'000'000), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {imus_on("IMU", 1), kDegraded, "rejecting CAMERA: utime -1 is negative"},
           {imus_on("CAMERA", 1), kRunning, ""},
       }},
      {"StartingIsDegradedByRejectionsButStoppingAndFailedAreKept", 0.0,
       {
           {advance_us(0), Status::STATE_STARTING, ""},
           {imus_on("IMU", -1), kDegraded, "rejecting IMU: utime -1 is negative"},
           {set_own_health(Status::STATE_FAILED, "camera lost"), Status::STATE_FAILED, "camera lost"},
           {imus_on("IMU", -2), Status::STATE_FAILED, "camera lost"},
           {set_own_health(Status::STATE_STOPPING, ""), Status::STATE_STOPPING, ""},
       }},
  };
}

class NodeHealthScript : public ::testing::TestWithParam<HealthScript> {};

// Every step's action is applied, then the heartbeat and health() are compared with what the
// step expects; the counters follow from the script (a negative utime or raw bytes: rejected).
TEST_P(NodeHealthScript, ReportsWhatEachStepExpects) {
  const HealthScript& script = GetParam();
  RejectingNode n(script.heartbeat_period_s);
  int64_t sent = 0, rejected = 0;
  for (size_t i = 0; i < script.steps.size(); ++i) {
    const Step& step = script.steps[i];
    SCOPED_TRACE("step " + std::to_string(i + 1) + ": " + describe(step.action));
    const Action& a = step.action;
    switch (a.kind) {
      case Action::Kind::kImu:
        for (int k = 0; k < a.count; ++k) {
          n.node.publish(a.text, imu(a.value + k));
          ++sent;
          if (a.value + k < 0) ++rejected;
        }
        break;
      case Action::Kind::kBytes:
        n.node.lcm().publish(a.text, a.bytes.data(), static_cast<unsigned int>(a.bytes.size()));
        ++sent;
        ++rejected;
        break;
      case Action::Kind::kSetHealth:
        n.node.set_health(static_cast<int8_t>(a.value), a.text);
        break;
      case Action::Kind::kAdvance:
        n.clock.now_us += a.value;
        break;
    }
    const Status& heartbeat = n.last();
    EXPECT_EQ(heartbeat.state, step.state);
    expect_message(heartbeat.message, step.message);
    const Node::Health health = n.node.health();
    EXPECT_EQ(health.state, step.state);
    expect_message(health.message, step.message);
    EXPECT_EQ(n.node.counters().messages_in, sent);
    EXPECT_EQ(n.node.counters().messages_rejected, rejected);
  }
}

INSTANTIATE_TEST_SUITE_P(NodeHealth, NodeHealthScript, ::testing::ValuesIn(health_scripts()),
                         [](const ::testing::TestParamInfo<HealthScript>& script) {
                           return std::string(script.param.name);
                         });

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
