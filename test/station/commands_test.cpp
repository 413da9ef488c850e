// The page's commands: their form, the token, the goal checks, and that a hold is what the
// follower already takes as "stop".
#include <gtest/gtest.h>

#include "control/follower_node.h"
#include "common/transport/convert.h"
#include "station/commands.h"

namespace kestrel::station {
namespace {

std::string refusal(std::string_view text, const std::string& token = "") {
  try {
    parse_command(text, token);
  } catch (const CommandError& e) {
    return e.what();
  }
  return "";
}

TEST(StationCommands, AGoalAndAHoldParse) {
  const Command goal = parse_command(R"({"cmd":"goal","goal":[1.5,-2,1,0.25]})", "");
  ASSERT_TRUE(std::holds_alternative<GoalCommand>(goal));
  EXPECT_EQ(std::get<GoalCommand>(goal).goal, (std::array<double, 4>{1.5, -2, 1, 0.25}));
  EXPECT_TRUE(std::holds_alternative<HoldCommand>(parse_command(R"({"cmd":"hold"})", "")));
}

TEST(StationCommands, TheTransportOfAReplayParsesAndNonsenseIsRefused) {
  const auto playback = [](std::string_view text) { return std::get<PlaybackCommand>(parse_command(text, "")); };
  EXPECT_EQ(playback(R"({"cmd":"play"})").command, kestrel::playback_command_t::COMMAND_PLAY);
  EXPECT_EQ(playback(R"({"cmd":"pause"})").command, kestrel::playback_command_t::COMMAND_PAUSE);
  EXPECT_DOUBLE_EQ(playback(R"({"cmd":"seek","t":12.5})").seek_s, 12.5);
  EXPECT_DOUBLE_EQ(playback(R"({"cmd":"speed","speed":0.25})").speed, 0.25);
  EXPECT_NE(refusal(R"({"cmd":"seek"})").find("\"t\" must be a finite number"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"seek","t":"3"})").find("finite number"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"seek","t":-1})").find("not negative"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"speed","speed":0})").find("above 0"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"speed","speed":1000})").find("at most 100"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"speed","speed":1e999})"), "");
  EXPECT_NE(refusal(R"({"cmd":"pause"})", "secret").find("token"), std::string::npos);
}

TEST(StationCommands, MalformedCommandsAreRefusedSayingWhy) {
  EXPECT_NE(refusal("{not json"), "");
  EXPECT_NE(refusal("[1,2]").find("not a JSON object"), std::string::npos);
  EXPECT_NE(refusal(R"({"goal":[1,2,3,4]})").find("no \"cmd\""), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"fly"})").find("unknown cmd"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"goal","goal":[1,2,3]})").find("[x, y, z, yaw]"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"goal","goal":[1,"2",3,4]})").find("numbers"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"goal","goal":[1,2,3e999,4]})"), "");  // overflows to inf, or is refused as JSON
  EXPECT_NE(refusal(std::string(kMaxCommandBytes + 1, ' ')).find("bytes refused"), std::string::npos);
}

TEST(StationCommands, WithATokenEveryCommandMustCarryIt) {
  const std::string token = "0123456789abcdef";
  EXPECT_NE(refusal(R"({"cmd":"hold"})", token).find("token"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"hold","token":"0123456789abcdeF"})", token).find("token"), std::string::npos);
  EXPECT_NE(refusal(R"({"cmd":"hold","token":7})", token).find("token"), std::string::npos);
  EXPECT_EQ(refusal(R"({"cmd":"hold","token":"0123456789abcdef"})", token), "");
  EXPECT_TRUE(token_matches("abc", "abc"));
  EXPECT_FALSE(token_matches("abc", "abd"));
  EXPECT_FALSE(token_matches("ab", "abc"));
  EXPECT_FALSE(token_matches("", "abc"));
}

CellSet room_map() {
  CellSet m;
  m.resolution_m = 0.1;
  m.known_bounds = Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, 0), Eigen::Vector3d(2, 2, 2.5));
  // One occupied cell: key (32778, 32768, 32778) = x in [1.0, 1.1), y in [0, 0.1), z in [1.0, 1.1).
  m.ids = {32778ull | (32768ull << 16) | (32778ull << 32)};
  m.cells = {{1.05f, 0.05f, 1.05f, 0.1f}};
  return m;
}

TEST(StationCommands, GoalsOutsideTheMapOrInOccupiedSpaceAreRefused) {
  const CellSet map = room_map();
  const GoalCheckOptions o;  // 0.2 m clearance
  EXPECT_NE(check_goal({{0, 0, 1, 0}}, nullptr, o).find("no map yet"), std::string::npos);
  EXPECT_NE(check_goal({{3, 0, 1, 0}}, &map, o).find("outside the map's bounds"), std::string::npos);
  EXPECT_NE(check_goal({{0, 0, 2.6, 0}}, &map, o).find("outside"), std::string::npos);
  EXPECT_NE(check_goal({{1.05, 0.05, 1.05, 0}}, &map, o).find("occupied"), std::string::npos);
  EXPECT_NE(check_goal({{1.25, 0.05, 1.05, 0}}, &map, o).find("occupied"), std::string::npos);  // 0.15 m away
  EXPECT_EQ(check_goal({{1.35, 0.05, 1.05, 0}}, &map, o), "");  // 0.25 m away
  EXPECT_EQ(check_goal({{0, 0, 1, 0}}, &map, o), "");
  EXPECT_NE(check_goal({{0, 0, 1, 1e6}}, &map, o), "");
}

TEST(StationCommands, TheRequestIsGotosAndTheHoldMakesTheFollowerHold) {
  const kestrel::plan_request_t r = plan_request({{1, 2, 1.2, 0.5}}, 77, 5'000'000);
  EXPECT_EQ(r.request_id, 77);
  EXPECT_EQ(r.start_mode, kestrel::plan_request_t::START_FROM_STATE);
  EXPECT_EQ(r.goal[0], 1);
  EXPECT_EQ(r.goal[3], 0.5);

  // A follower flying a path, then the station's hold: its next command is MODE_HOLD where
  // the vehicle is.
  control::FollowerNode follower({});
  kestrel::plan_t plan{};
  plan.status = kestrel::plan_t::STATUS_OK;
  plan.num_waypoints = 2;
  plan.waypoints = {{0, 0, 1, 0}, {3, 0, 1, 0}};
  plan.covariance_trace = {0, 0};
  follower.on_plan(plan);
  kestrel::state_t s{};
  s.utime = 1'000'000;
  s.status = kestrel::state_t::STATUS_OK;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.5, 0, 1);
  s.T_world_body = transport::to_message(T);
  auto command = follower.on_state(s);
  ASSERT_TRUE(command.has_value());
  EXPECT_EQ(command->mode, kestrel::vehicle_command_t::MODE_POSITION);
  follower.on_plan(hold_plan(78, s.utime));
  s.utime += 100'000;
  command = follower.on_state(s);
  ASSERT_TRUE(command.has_value());
  EXPECT_EQ(command->mode, kestrel::vehicle_command_t::MODE_HOLD);
  EXPECT_DOUBLE_EQ(command->position[0], 0.5);
}

}  // namespace
}  // namespace kestrel::station
