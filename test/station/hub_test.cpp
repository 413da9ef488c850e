// The browsers' mailboxes: newest per kind, bounded, map differences per client.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "station/hub.h"
#include "station/station.h"
#include "station/wire.h"

namespace kestrel::station {
namespace {

std::shared_ptr<const CellSet> cells(std::vector<uint64_t> ids) {
  auto s = std::make_shared<CellSet>();
  s->resolution_m = 0.1;
  for (uint64_t id : ids) {
    s->ids.push_back(id);
    s->cells.push_back({static_cast<float>(id), 0.f, 0.f, 0.1f});
  }
  return s;
}

TEST(StationHub, ASlowClientGetsTheNewestOfEachKindOnly) {
  UpdateHub hub;
  int wakes = 0;
  const auto id = hub.add_client([&] { ++wakes; });
  ASSERT_TRUE(id.has_value());
  for (int i = 0; i < 1000; ++i) hub.post("state", {false, "s" + std::to_string(i)});
  hub.post("plan", {false, "p"});
  const auto out = hub.take(*id);
  ASSERT_EQ(out.size(), 2u);  // bounded by the kinds, not by what was posted
  EXPECT_EQ(out[1].bytes, "s999");
  EXPECT_EQ(hub.stats().dropped, 999);
  EXPECT_GE(wakes, 1001);
  EXPECT_TRUE(hub.take(*id).empty());
}

TEST(StationHub, ALateClientStartsFromTheNewestOfEveryKindAndTheWholeMap) {
  UpdateHub hub;
  hub.post("graph", {false, "g"});
  hub.post_map(cells({1, 2, 3}));
  const auto id = hub.add_client({});
  const auto out = hub.take(*id);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].bytes, "g");
  size_t after = 0;
  const CellDiff d = decode_map_diff(out[1].bytes, &after);
  EXPECT_TRUE(d.reset);
  EXPECT_EQ(d.added.size(), 3u);
  EXPECT_EQ(after, 3u);
}

TEST(StationHub, EachClientGetsTheDifferenceFromWhatItHas) {
  UpdateHub hub;
  const auto fast = hub.add_client({}), slow = hub.add_client({});
  hub.post_map(cells({1, 2, 3}));
  hub.take(*fast);
  hub.take(*slow);
  hub.post_map(cells({2, 3, 4}));
  const CellDiff f = decode_map_diff(hub.take(*fast).at(0).bytes);
  EXPECT_EQ(f.added.size(), 1u);
  EXPECT_EQ(f.removed.size(), 1u);
  hub.post_map(cells({3, 4, 5, 6}));
  EXPECT_EQ(decode_map_diff(hub.take(*fast).at(0).bytes).added.size(), 2u);
  // The slow client skipped a map: one difference from {1,2,3} to {3,4,5,6}.
  const CellDiff s = decode_map_diff(hub.take(*slow).at(0).bytes);
  EXPECT_FALSE(s.reset);
  EXPECT_EQ(s.added.size(), 3u);
  EXPECT_EQ(s.removed.size(), 2u);
  hub.post_map(nullptr);
  size_t after = 99;
  EXPECT_TRUE(decode_map_diff(hub.take(*fast).at(0).bytes, &after).reset);
  EXPECT_EQ(after, 0u);
}

TEST(StationHub, ClientsBeyondTheLimitAreRefused) {
  UpdateHub hub(2);
  EXPECT_TRUE(hub.add_client({}).has_value());
  const auto b = hub.add_client({});
  EXPECT_TRUE(b.has_value());
  EXPECT_FALSE(hub.add_client({}).has_value());
  hub.remove_client(*b);
  EXPECT_TRUE(hub.add_client({}).has_value());
}

TEST(StationStation, ACommandIsAnsweredOnItsOwnSocketAndYieldsOneMessage) {
  UpdateHub hub;
  const auto a = hub.add_client({}), b = hub.add_client({});
  Station st({}, hub, 1000);
  hub.take(*a);
  hub.take(*b);
  CommandResult r = st.on_command(*a, R"({"cmd":"goal","goal":[0,0,1,0]})");
  EXPECT_FALSE(r.ok);  // no map yet
  EXPECT_FALSE(r.request.has_value());
  ASSERT_EQ(hub.take(*a).size(), 1u);
  EXPECT_TRUE(hub.take(*b).empty());
  r = st.on_command(*a, R"({"cmd":"hold"})");
  EXPECT_TRUE(r.ok);
  ASSERT_TRUE(r.hold.has_value());
  EXPECT_EQ(r.hold->request_id, 1000);
  EXPECT_EQ(r.hold->status, kestrel::plan_t::STATUS_NO_PATH);
  r = st.on_command(*b, "garbage");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(hub.take(*b).at(0).bytes.find("not a JSON object"), std::string::npos);
}

}  // namespace
}  // namespace kestrel::station

namespace kestrel::station {
namespace {

bool has_kind(const std::vector<Outgoing>& out, const std::string& kind) {
  for (const Outgoing& m : out)
    if (!m.binary && m.bytes.find("\"kind\":\"" + kind + "\"") != std::string::npos) return true;
  return false;
}

TEST(StationStation, APathThatDidNotGrowIsNotSentAgain) {
  UpdateHub hub;
  const auto id = hub.add_client({});
  Station st({}, hub, 1);
  kestrel::state_t s{};
  s.utime = 1'000'000;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body.orientation[0] = 1.0;
  s.T_world_body.position[2] = 1.0;
  st.on_state(s, "STATE");
  auto out = hub.take(*id);
  EXPECT_TRUE(has_kind(out, "state"));
  EXPECT_TRUE(has_kind(out, "path"));
  s.utime += 1'000'000;  // a second later, hovering where it was
  st.on_state(s, "STATE");
  out = hub.take(*id);
  EXPECT_TRUE(has_kind(out, "state"));
  EXPECT_FALSE(has_kind(out, "path"));
  s.utime += 1'000'000;
  s.T_world_body.position[0] = 0.5;  // moved: the path grew
  st.on_state(s, "STATE");
  EXPECT_TRUE(has_kind(hub.take(*id), "path"));
}

// A PLAN and its PLAN_COVARIANCE, in either order: the plan is drawn at once, and again with
// its ellipses once both are there; another plan's covariance changes nothing.
TEST(StationStation, APlanIsDrawnWithItsEllipsesWhicheverComesFirst) {
  kestrel::plan_t plan{};
  plan.utime = 7;
  plan.request_id = 3;
  plan.num_waypoints = 1;
  plan.waypoints = {{1, 2, 1, 0}};
  plan.covariance_trace = {0.2};
  kestrel::plan_covariance_t covariance{};
  covariance.utime = 7;
  covariance.request_id = 3;
  covariance.num_waypoints = 1;
  covariance.covariance = {{0.04, 0, 0, 0, 0, 0.01, 0, 0, 0, 0, 0.1, 0, 0, 0, 0, 0.05}};
  const auto ellipses_in = [](const std::vector<Outgoing>& out) {
    for (const Outgoing& m : out)
      if (!m.binary && m.bytes.find("\"kind\":\"plan\"") != std::string::npos)
        return m.bytes.find("\"ellipses\"") != std::string::npos ? 1 : 0;
    return -1;  // no plan sent
  };
  for (const bool covariance_first : {false, true}) {
    UpdateHub hub;
    const auto id = hub.add_client({});
    Station st({}, hub, 1);
    hub.take(*id);
    if (covariance_first) {
      st.on_plan_covariance(covariance, "PLAN_COVARIANCE");
      EXPECT_EQ(ellipses_in(hub.take(*id)), -1) << "no plan to draw yet";
      st.on_plan(plan, "PLAN");
      EXPECT_EQ(ellipses_in(hub.take(*id)), 1);
    } else {
      st.on_plan(plan, "PLAN");
      EXPECT_EQ(ellipses_in(hub.take(*id)), 0);
      kestrel::plan_covariance_t other = covariance;
      other.request_id = 4;
      st.on_plan_covariance(other, "PLAN_COVARIANCE");
      EXPECT_EQ(ellipses_in(hub.take(*id)), -1);
      st.on_plan_covariance(covariance, "PLAN_COVARIANCE");
      EXPECT_EQ(ellipses_in(hub.take(*id)), 1);
    }
  }
}

// A controlled replay's transport: nothing is sent before the replay has said where it is, a
// seek beyond its log is refused, and a new seek count forgets the flight drawn so far.
TEST(StationStation, TheTransportBarDrivesAControlledReplayOnly) {
  UpdateHub hub;
  const auto id = hub.add_client({});
  Station st({}, hub, 500);
  CommandResult r = st.on_command(*id, R"({"cmd":"pause"})");
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.playback.has_value());
  EXPECT_NE(r.notice.find("no replay to control"), std::string::npos) << r.notice;

  kestrel::playback_status_t p{};
  p.start_utime = 10'000'000;
  p.end_utime = 30'000'000;
  p.utime = 15'000'000;
  p.speed = 1.0;
  p.log_name = "flight.lcmlog";
  st.on_playback(p, "PLAYBACK_STATUS");
  auto out = hub.take(*id);
  ASSERT_TRUE(has_kind(out, "playback"));
  for (const Outgoing& m : out)
    if (m.bytes.find("\"kind\":\"playback\"") != std::string::npos) {
      const auto j = nlohmann::json::parse(m.bytes);
      EXPECT_DOUBLE_EQ(j["t"].get<double>(), 5.0);
      EXPECT_DOUBLE_EQ(j["length"].get<double>(), 20.0);
    }
  r = st.on_command(*id, R"({"cmd":"seek","t":12.5})");
  ASSERT_TRUE(r.ok) << r.notice;
  ASSERT_TRUE(r.playback.has_value());
  EXPECT_EQ(r.playback->command, kestrel::playback_command_t::COMMAND_SEEK);
  EXPECT_EQ(r.playback->seek_utime, 22'500'000);
  EXPECT_EQ(r.playback->request_id, 500);
  r = st.on_command(*id, R"({"cmd":"seek","t":20.5})");
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.playback.has_value());
  EXPECT_NE(r.notice.find("the log is 20.0 s long"), std::string::npos) << r.notice;
  r = st.on_command(*id, R"({"cmd":"speed","speed":4})");
  ASSERT_TRUE(r.playback.has_value());
  EXPECT_EQ(r.playback->command, kestrel::playback_command_t::COMMAND_SPEED);
  EXPECT_DOUBLE_EQ(r.playback->speed, 4.0);

  // The flight so far, then a seek: the path is forgotten.
  kestrel::state_t s{};
  s.utime = 15'000'000;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body.orientation[0] = 1.0;
  st.on_state(s, "STATE");
  hub.take(*id);
  p.seeks = 1;
  p.utime = 22'500'000;
  st.on_playback(p, "PLAYBACK_STATUS");
  out = hub.take(*id);
  bool empty_path = false;
  for (const Outgoing& m : out)
    if (m.bytes.find("\"kind\":\"path\"") != std::string::npos)
      empty_path = nlohmann::json::parse(m.bytes)["points"].empty();
  EXPECT_TRUE(empty_path) << "the path of before the seek is still drawn";

  // A status off the bus that cannot be drawn changes nothing.
  p.end_utime = p.start_utime - 1;
  EXPECT_THROW(st.on_playback(p, "PLAYBACK_STATUS"), InputError);
  p.end_utime = 30'000'000;
  p.speed = std::nan("");
  EXPECT_THROW(st.on_playback(p, "PLAYBACK_STATUS"), InputError);
}

}  // namespace
}  // namespace kestrel::station
