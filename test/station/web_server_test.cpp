// The station's server on loopback, with civetweb's own WebSocket client: the page's files,
// updates reaching a browser, commands reaching the inbox, and the refusals — no token or a
// wrong one, a foreign Origin, an oversized message.
#include <gtest/gtest.h>

#include <civetweb.h>

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>

#include "station/commands.h"
#include "station/web_server.h"
#include "test/support/test_support.h"

namespace kestrel::station {
namespace {

// What a client received, with a way to wait for it.
struct Received {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<std::string> messages;
  bool closed = false;

  static int on_data(mg_connection*, int bits, char* data, size_t len, void* self) {
    auto* r = static_cast<Received*>(self);
    const int opcode = bits & 0xf;
    if (opcode == MG_WEBSOCKET_OPCODE_TEXT || opcode == MG_WEBSOCKET_OPCODE_BINARY) {
      std::lock_guard lock(r->mutex);
      r->messages.emplace_back(data, len);
    }
    r->cv.notify_all();
    return 1;
  }
  static void on_close(const mg_connection*, void* self) {
    auto* r = static_cast<Received*>(self);
    {
      std::lock_guard lock(r->mutex);
      r->closed = true;
    }
    r->cv.notify_all();
  }
  template <class Pred>
  bool wait(Pred pred) {
    std::unique_lock lock(mutex);
    return cv.wait_for(lock, std::chrono::seconds(10), pred);
  }
};

class StationWebServer : public ::testing::Test {
 protected:
  void start(const std::string& token) {
    std::ofstream(dir_ / "index.html") << "<html>station</html>";
    WebServerOptions o;
    o.port = 0;  // any free port
    o.document_root = dir_.path().string();
    o.token = token;
    o.max_clients = 2;
    server_ = std::make_unique<WebServer>(o, hub_);
    ASSERT_GT(server_->port(), 0);
  }
  // A socket to /ws`query`, with `origin` (the page's own when empty); null if refused.
  // civetweb's client sends "Host: 127.0.0.1" without the port (a browser sends the port, and
  // then the page's origin has it too), so the page's own origin here is http://127.0.0.1.
  mg_connection* connect(Received& r, const std::string& query, std::string origin = "") {
    if (origin.empty()) origin = "http://127.0.0.1";
    char error[256] = "";
    const std::string path = "/ws" + query;
    mg_connection* c = mg_connect_websocket_client("127.0.0.1", server_->port(), 0, error, sizeof error, path.c_str(),
                                                   origin.c_str(), &Received::on_data, &Received::on_close, &r);
    return c;
  }
  // Commands reach the inbox on the server's threads: wait for `n`.
  std::vector<std::pair<UpdateHub::ClientId, std::string>> commands(size_t n) {
    std::vector<std::pair<UpdateHub::ClientId, std::string>> all;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (all.size() < n && std::chrono::steady_clock::now() < deadline) {
      for (auto& c : server_->take_commands()) all.push_back(std::move(c));
      if (all.size() < n) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return all;
  }

  test::TempDir dir_;
  UpdateHub hub_{2};
  std::unique_ptr<WebServer> server_;
};

TEST_F(StationWebServer, ServesThePageAndCarriesUpdatesAndCommands) {
  start("");
  char error[256] = "";
  mg_connection* http = mg_download("127.0.0.1", server_->port(), 0, error, sizeof error, "GET /index.html HTTP/1.0\r\n\r\n");
  ASSERT_NE(http, nullptr) << error;
  char body[64] = "";
  const int n = mg_read(http, body, sizeof body - 1);
  mg_close_connection(http);
  EXPECT_EQ(std::string(body, static_cast<size_t>(std::max(n, 0))), "<html>station</html>");

  hub_.post("health", {false, "{\"kind\":\"health\"}"});
  Received r;
  mg_connection* ws = connect(r, "");
  ASSERT_NE(ws, nullptr);
  ASSERT_TRUE(r.wait([&] { return !r.messages.empty(); })) << "the newest health update never came";
  EXPECT_EQ(r.messages[0], "{\"kind\":\"health\"}");
  hub_.post("state", {false, "s1"});
  ASSERT_TRUE(r.wait([&] { return r.messages.size() >= 2; }));
  EXPECT_EQ(r.messages[1], "s1");

  const std::string command = R"({"cmd":"hold"})";
  ASSERT_GT(mg_websocket_client_write(ws, MG_WEBSOCKET_OPCODE_TEXT, command.data(), command.size()), 0);
  const auto got = commands(1);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].second, command);
  mg_close_connection(ws);
}

TEST_F(StationWebServer, WithATokenASocketNeedsIt) {
  start("0123456789abcdef");
  Received none, wrong, right;
  EXPECT_EQ(connect(none, ""), nullptr);
  EXPECT_EQ(connect(wrong, "?token=0123456789abcdeX"), nullptr);
  mg_connection* ws = connect(right, "?token=0123456789abcdef");
  ASSERT_NE(ws, nullptr);
  mg_close_connection(ws);
}

TEST_F(StationWebServer, ASocketFromAnotherSiteIsRefused) {
  start("");
  Received r;
  EXPECT_EQ(connect(r, "", "http://example.com"), nullptr);
}

TEST_F(StationWebServer, AnOversizedMessageClosesTheSocketAndIsNotACommand) {
  start("");
  Received r;
  mg_connection* ws = connect(r, "");
  ASSERT_NE(ws, nullptr);
  const std::string huge(kMaxCommandBytes + 1, 'x');
  mg_websocket_client_write(ws, MG_WEBSOCKET_OPCODE_TEXT, huge.data(), huge.size());
  EXPECT_TRUE(r.wait([&] { return r.closed; })) << "the server kept the socket";
  EXPECT_TRUE(server_->take_commands().empty());
  mg_close_connection(ws);
}

TEST_F(StationWebServer, ClientsBeyondTheLimitAreRefused) {
  start("");
  Received a, b, c;
  mg_connection* first = connect(a, "");
  mg_connection* second = connect(b, "");
  ASSERT_NE(first, nullptr);
  ASSERT_NE(second, nullptr);
  ASSERT_TRUE(a.wait([&] { return hub_.clients() == 2; }));
  EXPECT_EQ(connect(c, ""), nullptr);
  mg_close_connection(first);
  mg_close_connection(second);
}

TEST(StationLoopback, OnlyLoopbackAddressesNeedNoToken) {
  EXPECT_TRUE(is_loopback("127.0.0.1"));
  EXPECT_TRUE(is_loopback("127.1.2.3"));
  EXPECT_TRUE(is_loopback("localhost"));
  EXPECT_TRUE(is_loopback("::1"));
  EXPECT_FALSE(is_loopback("0.0.0.0"));
  EXPECT_FALSE(is_loopback("192.168.1.5"));
  EXPECT_FALSE(is_loopback("::"));
}

}  // namespace
}  // namespace kestrel::station
