// AckLedger: the lock-step accounting on hand-made process graphs.

#include <gtest/gtest.h>

#include "tools/replay/ack_ledger.h"

namespace kestrel::replay {
namespace {

// CAMERA_RGBD -> codec-z -> Z -> codec-raw -> RAW; IMU -> est -> STATE.
ConsumerMap chain() {
  return {{"CAMERA_RGBD", {"codec-z"}}, {"Z", {"codec-raw"}}, {"IMU", {"est"}}};
}
auto record_none = [](const std::string&) { return false; };
auto record_outputs = [](const std::string& c) { return c == "Z" || c == "RAW" || c == "STATE"; };

TEST(AckLedger, FollowsAChainToTheEnd) {
  AckLedger ledger(chain(), record_none);
  ledger.publish("CAMERA_RGBD");
  EXPECT_FALSE(ledger.settled());
  EXPECT_EQ(ledger.awaited_acks(), 1);
  EXPECT_TRUE(ledger.owes("codec-z"));
  ledger.acknowledge("codec-z", "CAMERA_RGBD", {"Z"});
  EXPECT_FALSE(ledger.settled());
  EXPECT_TRUE(ledger.owes("codec-raw"));
  EXPECT_FALSE(ledger.owes("codec-z"));
  ledger.acknowledge("codec-raw", "Z", {"RAW"});  // nobody consumes RAW
  EXPECT_TRUE(ledger.settled());
  EXPECT_EQ(ledger.finish_event(), 0);
}

TEST(AckLedger, AnInputNobodyConsumesIsSettledAtOnce) {
  AckLedger ledger(chain(), record_none);
  ledger.publish("GROUND_TRUTH");
  EXPECT_TRUE(ledger.settled());
}

TEST(AckLedger, FanOutWaitsForEveryConsumer) {
  AckLedger ledger({{"VO_UPDATE", {"est", "slam"}}}, record_none);
  ledger.publish("VO_UPDATE");
  ledger.acknowledge("slam", "VO_UPDATE", {});
  EXPECT_FALSE(ledger.settled());
  EXPECT_TRUE(ledger.owes("est"));
  ledger.acknowledge("est", "VO_UPDATE", {"STATE"});
  EXPECT_TRUE(ledger.settled());
}

TEST(AckLedger, ToleratesAnAcknowledgementOvertakingItsCause) {
  // codec-raw's ack for Z arrives before codec-z's ack that announces Z.
  AckLedger ledger(chain(), record_none);
  ledger.publish("CAMERA_RGBD");
  ledger.acknowledge("codec-raw", "Z", {});
  EXPECT_FALSE(ledger.settled());
  ledger.acknowledge("codec-z", "CAMERA_RGBD", {"Z"});
  EXPECT_TRUE(ledger.settled());
}

// A process that joined during the event (sim --lockstep, a restart) owed nothing, but what it
// published is an input of the others, whose acknowledgements are then awaited.
TEST(AckLedger, AnAnnouncementWithoutAnInputExpectsTheConsumersOfItsOutputs) {
  AckLedger ledger({{"IMU", {"est"}}, {"STATE", {"follow"}}}, record_none);
  ledger.publish("IMU");
  ledger.announce({"STATE"});  // a newcomer's STATE
  ledger.acknowledge("est", "IMU", {"STATE"});
  EXPECT_FALSE(ledger.settled());
  EXPECT_EQ(ledger.awaited_acks(), 2);
  ledger.acknowledge("follow", "STATE", {});
  EXPECT_FALSE(ledger.settled());
  ledger.acknowledge("follow", "STATE", {});
  EXPECT_TRUE(ledger.settled());
}

// A process that left (killed in flight) owes nothing more, now or in later events.
TEST(AckLedger, AForgottenProcessIsOwedNothingAndNoLongerAConsumer) {
  AckLedger ledger({{"IMU", {"est", "slam"}}}, record_none);
  ledger.publish("IMU");
  ledger.acknowledge("slam", "IMU", {});
  EXPECT_TRUE(ledger.owes("est"));
  ledger.forget("est");
  EXPECT_FALSE(ledger.owes("est"));
  EXPECT_TRUE(ledger.settled());
  ledger.finish_event();
  ledger.publish("IMU");
  EXPECT_FALSE(ledger.owes("est"));
  ledger.acknowledge("slam", "IMU", {});
  EXPECT_TRUE(ledger.settled());
}

TEST(AckLedger, AnUnexpectedAcknowledgementKeepsTheEventOpenAndIsExplained) {
  AckLedger ledger(chain(), record_none);
  ledger.publish("CAMERA_RGBD");
  ledger.acknowledge("codec-z", "CAMERA_RGBD", {});
  ledger.acknowledge("est", "IMU", {});  // an IMU the replay never sent
  EXPECT_FALSE(ledger.settled());
  const auto owed = ledger.outstanding();
  ASSERT_EQ(owed.size(), 1u);
  EXPECT_EQ(owed[0].process, "est");
  EXPECT_EQ(owed[0].count, -1);
  EXPECT_NE(explain(owed[0]).find("est acknowledged 1 IMU input(s) the replay did not send"),
            std::string::npos)
      << explain(owed[0]);
}

TEST(AckLedger, ExplainsAMissingAcknowledgement) {
  AckLedger ledger(chain(), record_none);
  ledger.publish("CAMERA_RGBD");
  ledger.acknowledge("codec-z", "CAMERA_RGBD", {"Z"});
  const auto owed = ledger.outstanding();
  ASSERT_EQ(owed.size(), 1u);
  EXPECT_EQ(explain(owed[0]), "codec-raw did not acknowledge 1 Z input(s)");
}

TEST(AckLedger, WaitsForEveryAnnouncedRecordedMessage) {
  AckLedger ledger(chain(), record_outputs);
  ledger.publish("CAMERA_RGBD");
  ledger.acknowledge("codec-z", "CAMERA_RGBD", {"Z"});
  ledger.acknowledge("codec-raw", "Z", {"RAW", "RAW"});
  ledger.receive("Z");
  ledger.receive("RAW");
  EXPECT_FALSE(ledger.settled());
  const auto owed = ledger.outstanding();
  ASSERT_EQ(owed.size(), 1u);
  EXPECT_EQ(explain(owed[0]), "1 message(s) on RAW announced in acknowledgements but never received");
  ledger.receive("RAW");
  EXPECT_TRUE(ledger.settled());
  EXPECT_EQ(ledger.finish_event(), 0);
}

TEST(AckLedger, AMessageMayArriveBeforeTheAcknowledgementThatAnnouncesIt) {
  AckLedger ledger(chain(), record_outputs);
  ledger.publish("IMU");
  ledger.receive("STATE");
  EXPECT_FALSE(ledger.settled());
  ledger.acknowledge("est", "IMU", {"STATE"});
  EXPECT_TRUE(ledger.settled());
}

TEST(AckLedger, CountsMessagesPublishedOutsideAnyHandler) {
  AckLedger ledger(chain(), record_outputs);
  ledger.publish("IMU");
  ledger.acknowledge("est", "IMU", {});
  ledger.receive("STATE");  // nobody announced it: a timer, not a handler
  ledger.receive("STATE");
  EXPECT_TRUE(ledger.settled());
  EXPECT_EQ(ledger.finish_event(), 2);
  // The next event starts from zero.
  ledger.publish("IMU");
  ledger.acknowledge("est", "IMU", {});
  EXPECT_TRUE(ledger.settled());
  EXPECT_EQ(ledger.finish_event(), 0);
}

}  // namespace
}  // namespace kestrel::replay
