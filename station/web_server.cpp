#include "station/web_server.h"

#include <civetweb.h>

#include <condition_variable>
#include <cstring>
#include <thread>

#include "common/error.h"
#include "station/commands.h"
#include "station/station.h"

namespace kestrel::station {

struct WebServer::Session {
  mg_connection* conn = nullptr;
  UpdateHub::ClientId id = 0;
  std::mutex mutex;
  std::condition_variable cv;
  bool pending = true;
  bool closing = false;
  std::thread sender;
};

namespace {

// The value of `key` in a query string "a=1&token=xyz" ("" if absent). Tokens are hex, so no
// percent-decoding is needed; a token that needed it would not match anyway.
std::string query_value(const char* query, const std::string& key) {
  if (!query) return "";
  const std::string q(query);
  size_t at = 0;
  while (at <= q.size()) {
    const size_t end = std::min(q.find('&', at), q.size());
    const std::string pair = q.substr(at, end - at);
    if (pair.compare(0, key.size() + 1, key + "=") == 0) return pair.substr(key.size() + 1);
    at = end + 1;
  }
  return "";
}

void send_loop(WebServer::Session* s, UpdateHub* hub) {
  for (;;) {
    {
      std::unique_lock lock(s->mutex);
      s->cv.wait(lock, [&] { return s->pending || s->closing; });
      if (s->closing) return;
      s->pending = false;
    }
    for (const Outgoing& m : hub->take(s->id)) {
      const int opcode = m.binary ? MG_WEBSOCKET_OPCODE_BINARY : MG_WEBSOCKET_OPCODE_TEXT;
      if (mg_websocket_write(s->conn, opcode, m.bytes.data(), m.bytes.size()) <= 0) {
        // The browser is gone; its connection thread will see that too and close.
        std::unique_lock lock(s->mutex);
        s->cv.wait(lock, [&] { return s->closing; });
        return;
      }
    }
  }
}

}  // namespace

bool is_loopback(const std::string& a) {
  return a == "localhost" || a == "::1" || a == "[::1]" || a.rfind("127.", 0) == 0;
}

WebServer::WebServer(const WebServerOptions& options, UpdateHub& hub) : options_(options), hub_(hub) {
  mg_init_library(0);
  if (!mg_check_feature(MG_FEATURES_WEBSOCKET)) throw UnavailableError("civetweb was built without WebSocket support");
  const std::string listen = (options.bind.find(':') != std::string::npos && options.bind.front() != '['
                                  ? "[" + options.bind + "]" : options.bind) + ":" + std::to_string(options.port);
  const std::string threads = std::to_string(options.max_clients + 4);
  const char* civet_options[] = {"listening_ports", listen.c_str(),
                                 "document_root", options.document_root.c_str(),
                                 "num_threads", threads.c_str(),
                                 "enable_directory_listing", "no",
                                 // An idle socket is pinged, not closed: the page only listens.
                                 "websocket_timeout_ms", "5000",
                                 "enable_websocket_ping_pong", "yes",
                                 nullptr};
  mg_callbacks callbacks{};
  // civetweb reports its errors through log_message; a failed start is reported below.
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };
  ctx_ = mg_start(&callbacks, this, civet_options);
  if (!ctx_) throw UnavailableError("cannot serve http on " + listen + " (address in use, or not ours?)");
  mg_server_port ports[4];
  const int n = mg_get_server_ports(ctx_, 4, ports);
  port_ = n > 0 ? ports[0].port : options.port;
  mg_set_websocket_handler(ctx_, "/ws", &WebServer::on_connect, &WebServer::on_ready, &WebServer::on_data,
                           &WebServer::on_close, this);
}

WebServer::~WebServer() {
  if (ctx_) mg_stop(ctx_);  // closes every socket: on_close joins each sender
}

std::vector<std::pair<UpdateHub::ClientId, std::string>> WebServer::take_commands() {
  std::lock_guard lock(inbox_mutex_);
  return std::exchange(inbox_, {});
}

int WebServer::on_connect(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  const mg_request_info* info = mg_get_request_info(conn);
  if (!self->options_.token.empty() && !token_matches(query_value(info->query_string, "token"), self->options_.token))
    return 1;
  const char* origin = mg_get_header(conn, "Origin");
  const char* host = mg_get_header(conn, "Host");
  if (origin && (!host || (std::string(origin) != std::string("http://") + host && std::string(origin) != std::string("https://") + host)))
    return 1;
  return self->hub_.clients() < self->options_.max_clients ? 0 : 1;
}

void WebServer::on_ready(mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  // Shared with the hub's wake function, which the producer may still be calling when the
  // socket closes: the session outlives both.
  auto* holder = new std::shared_ptr<Session>(std::make_shared<Session>());
  Session* s = holder->get();
  s->conn = conn;
  const auto id = self->hub_.add_client([session = *holder] {
    {
      std::lock_guard lock(session->mutex);
      session->pending = true;
    }
    session->cv.notify_one();
  });
  if (!id) {  // full since on_connect: this socket gets nothing and is closed by on_data
    s->closing = true;
  } else {
    s->id = *id;
    s->sender = std::thread(send_loop, s, &self->hub_);
  }
  mg_set_user_connection_data(conn, holder);
}

int WebServer::on_data(mg_connection* conn, int bits, char* data, size_t len, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  auto* holder = static_cast<std::shared_ptr<Session>*>(mg_get_user_connection_data(conn));
  Session* s = holder ? holder->get() : nullptr;
  const int opcode = bits & 0xf;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE || !s || s->id == 0) return 0;
  if (opcode != MG_WEBSOCKET_OPCODE_TEXT) return 1;  // pings, pongs; the page sends text only
  if (len > kMaxCommandBytes) return 0;              // not a command: drop the socket
  std::lock_guard lock(self->inbox_mutex_);
  if (self->inbox_.size() >= kMaxInbox) {
    self->hub_.post_to(s->id, "notice", Outgoing{false, json_text({{"kind", "notice"}, {"ok", false},
                                                                   {"text", "command refused: too many waiting"}})});
    return 1;
  }
  self->inbox_.emplace_back(s->id, std::string(data, len));
  return 1;
}

void WebServer::on_close(const mg_connection* conn, void* self_ptr) {
  auto* self = static_cast<WebServer*>(self_ptr);
  auto* holder = static_cast<std::shared_ptr<Session>*>(mg_get_user_connection_data(conn));
  if (!holder) return;
  Session* s = holder->get();
  {
    std::lock_guard lock(s->mutex);
    s->closing = true;
  }
  s->cv.notify_one();
  if (s->sender.joinable()) s->sender.join();
  if (s->id != 0) self->hub_.remove_client(s->id);
  delete holder;
}

}  // namespace kestrel::station
