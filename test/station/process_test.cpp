// kestrel-station as a process on a private network, driven through its socket by civetweb's
// own WebSocket client (no browser): off loopback it prints a token and refuses sockets and
// commands without it; a goal on the map goes out as a PLAN_REQUEST with exactly that goal, a
// goal in an occupied cell or malformed JSON sends nothing, and HOLD sends a PLAN without a path.
#include <gtest/gtest.h>

#include <civetweb.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <regex>
#include <thread>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "mapper/octree_io.h"
#include "test/support/live_system.h"

namespace kestrel {
namespace {

// The notices the page would show, as the socket delivers them.
struct Notices {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<nlohmann::json> notices;

  static int on_data(mg_connection*, int bits, char* data, size_t len, void* self) {
    auto* n = static_cast<Notices*>(self);
    if ((bits & 0xf) != MG_WEBSOCKET_OPCODE_TEXT) return 1;
    const auto j = nlohmann::json::parse(std::string(data, len), nullptr, false);
    const auto kind = j.is_object() ? j.find("kind") : j.end();
    if (kind != j.end() && *kind == "notice") {
      std::lock_guard lock(n->mutex);
      n->notices.push_back(j);
      n->cv.notify_all();
    }
    return 1;
  }
  // The `index`-th notice, waited for at most 10 s.
  std::optional<nlohmann::json> wait(size_t index) {
    std::unique_lock lock(mutex);
    if (!cv.wait_for(lock, std::chrono::seconds(10), [&] { return notices.size() > index; })) return std::nullopt;
    return notices[index];
  }
};

mg_connection* open_socket(int port, const std::string& query, Notices& n) {
  char error[256] = "";
  // civetweb's client sends "Host: 127.0.0.1" without the port: that is the page's origin here.
  return mg_connect_websocket_client("127.0.0.1", port, 0, error, sizeof error, ("/ws" + query).c_str(),
                                     "http://127.0.0.1", &Notices::on_data, nullptr, &n);
}

void send(mg_connection* c, const std::string& text) {
  ASSERT_GT(mg_websocket_client_write(c, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size()), 0);
}

// A map with known bounds (-1..2 m in x and y, 0..2 m up) and one occupied cell at
// (1.05, 0.05, 1.05), as the mapper publishes it.
kestrel::octomap_t small_map() {
  mapper::MapOptions o;
  o.resolution_m = 0.1;
  mapper::VoxelMap map(o);
  mapper::Key k;
  map.keys().key(1.05, 0.05, 1.05, k);
  map.set(k, 2.0f);
  for (double c : {-0.95, 1.95}) {
    map.keys().key(c, c, c < 0 ? 0.05 : 1.95, k);
    map.set(k, -2.0f);
  }
  kestrel::octomap_t m{};
  m.utime = 5'000'000;
  m.revision = 1;
  m.resolution = 0.1;
  m.format = kestrel::octomap_t::FORMAT_BINARY;
  m.data = mapper::encode_octree(map, mapper::OctreeFormat::kBinary);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

TEST(StationProcess, OffLoopbackATokenGuardsEverySocketAndCommand) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  test::TempDir dir;
  test::LiveSystem::Options options;
  options.channels = {channel::kPlanRequest, channel::kPlan};
  test::LiveSystem sys(dir.path(), options);
  // 0.0.0.0 inside the test's own network namespace: only its loopback is there.
  sys.start("station", {test::tool("station").string(), "--bind", "0.0.0.0", "--port", "8766"});
  ASSERT_NE(sys.wait_running("station"), 0) << sys.output("station");
  std::smatch token;
  const std::string out = sys.output("station");
  ASSERT_TRUE(std::regex_search(out, token, std::regex("http://0\\.0\\.0\\.0:8766/\\?token=([0-9a-f]{32})\\n")))
      << "no address with a 128-bit token printed: " << out;

  Notices none, wrong, right;
  EXPECT_EQ(open_socket(8766, "", none), nullptr) << "a socket without the token was let in";
  EXPECT_EQ(open_socket(8766, "?token=" + std::string(32, '0'), wrong), nullptr);
  mg_connection* c = open_socket(8766, "?token=" + token[1].str(), right);
  ASSERT_NE(c, nullptr);

  lcm::LCM lcm(transport::resolve_lcm_url(""));
  ASSERT_TRUE(lcm.good());
  const kestrel::octomap_t map = small_map();
  lcm.publish(channel::kMapOctomap, &map);

  // A command without the token is refused, though the socket had it.
  send(c, R"({"cmd":"hold"})");
  auto n = right.wait(0);
  ASSERT_TRUE(n.has_value());
  EXPECT_FALSE((*n)["ok"].get<bool>());
  EXPECT_NE((*n)["text"].get<std::string>().find("token"), std::string::npos) << n->dump();

  const std::string t = ",\"token\":\"" + token[1].str() + "\"}";
  send(c, "{not json" + t);
  n = right.wait(1);
  ASSERT_TRUE(n.has_value());
  EXPECT_FALSE((*n)["ok"].get<bool>());
  // The map may reach the station after the first commands: ask until it has it.
  size_t next = 2;
  for (int attempt = 0; attempt < 50; ++attempt) {
    send(c, R"({"cmd":"goal","goal":[1.05,0.05,1.05,0])" + t);  // the occupied cell
    n = right.wait(next++);
    ASSERT_TRUE(n.has_value());
    if ((*n)["text"].get<std::string>().find("no map yet") == std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_FALSE((*n)["ok"].get<bool>());
  EXPECT_NE((*n)["text"].get<std::string>().find("occupied"), std::string::npos) << n->dump();
  send(c, R"({"cmd":"goal","goal":[0.5,-0.25,1.0,0.3])" + t);
  n = right.wait(next++);
  ASSERT_TRUE(n.has_value());
  EXPECT_TRUE((*n)["ok"].get<bool>()) << n->dump();
  send(c, R"({"cmd":"hold")" + t);
  n = right.wait(next++);
  ASSERT_TRUE(n.has_value());
  EXPECT_TRUE((*n)["ok"].get<bool>()) << n->dump();

  const auto request = sys.wait_for<kestrel::plan_request_t>(
      channel::kPlanRequest, [](const kestrel::plan_request_t&) { return true; }, 10.0, "the goal's PLAN_REQUEST");
  ASSERT_TRUE(request.has_value());
  EXPECT_EQ(request->goal[0], 0.5);
  EXPECT_EQ(request->goal[1], -0.25);
  EXPECT_EQ(request->goal[2], 1.0);
  EXPECT_EQ(request->goal[3], 0.3);
  EXPECT_EQ(request->utime, map.utime) << "stamped with the newest sensor time the station saw";
  const auto hold = sys.wait_for<kestrel::plan_t>(
      channel::kPlan, [](const kestrel::plan_t&) { return true; }, 10.0, "the hold's PLAN");
  ASSERT_TRUE(hold.has_value());
  EXPECT_EQ(hold->status, kestrel::plan_t::STATUS_NO_PATH);
  EXPECT_EQ(hold->num_waypoints, 0);
  mg_close_connection(c);
  EXPECT_EQ(sys.stop("station"), 0) << sys.output("station");
  // Exactly one request and one plan: nothing for the refused commands.
  EXPECT_EQ(sys.messages(channel::kPlanRequest).size(), 1u);
  EXPECT_EQ(sys.messages(channel::kPlan).size(), 1u);
}

}  // namespace
}  // namespace kestrel
