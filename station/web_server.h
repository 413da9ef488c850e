#pragma once
// The station's HTTP and WebSocket server, on civetweb (Debian's libcivetweb; why civetweb:
// docs/decisions/2026-12-05-station-web-server.md). It serves the page's files from one
// folder and, on /ws, gives every browser a socket fed from the UpdateHub by a sender thread
// of its own, and hands the browsers' commands to the LCM thread through a bounded inbox.
//
// Invariants:
//  * With a token, a socket opens only with ?token=<token> in its URL (and every command
//    carries it too, checked by Station); a socket whose Origin is not the page's own host is
//    refused whatever the token, so another web site open in the same browser cannot command
//    the vehicle through it.
//  * A browser that reads slowly only blocks its own sender thread; the hub keeps the newest
//    of each kind for it meanwhile. Commands longer than kMaxCommandBytes close the socket,
//    and at most kMaxInbox commands wait (more are refused with a notice).
//  * The destructor stops the server: every socket is closed and every sender joined.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "station/hub.h"

struct mg_context;
struct mg_connection;

namespace kestrel::station {

struct WebServerOptions {
  std::string bind = "127.0.0.1";  ///< address to listen on
  int port = 8765;                 ///< 0: any free port (port() says which)
  std::string document_root;       ///< the page's files
  std::string token;               ///< "" = none required
  size_t max_clients = 8;
};

/// Whether `address` is a loopback address (127.0.0.0/8, ::1, localhost).
bool is_loopback(const std::string& address);

class WebServer {
 public:
  static constexpr size_t kMaxInbox = 64;
  /// Throws UnavailableError if civetweb lacks WebSocket support or cannot listen.
  WebServer(const WebServerOptions& options, UpdateHub& hub);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const { return port_; }
  /// The commands received since the last call, oldest first.
  std::vector<std::pair<UpdateHub::ClientId, std::string>> take_commands();

  struct Session;

 private:
  static int on_connect(const mg_connection* conn, void* self);
  static void on_ready(mg_connection* conn, void* self);
  static int on_data(mg_connection* conn, int bits, char* data, size_t len, void* self);
  static void on_close(const mg_connection* conn, void* self);

  WebServerOptions options_;
  UpdateHub& hub_;
  mg_context* ctx_ = nullptr;
  int port_ = 0;
  std::mutex inbox_mutex_;
  std::vector<std::pair<UpdateHub::ClientId, std::string>> inbox_;
};

}  // namespace kestrel::station
