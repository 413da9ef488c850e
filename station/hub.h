#pragma once
// The mailboxes between the station's one producer (the LCM thread) and its browsers (one
// sender thread each): a slow browser gets the newest of each kind, never a growing queue.
//
// Invariants:
//  * Per client, at most one message waits per kind (a newer one replaces it, and the
//    replacement is counted as dropped), plus the map: so what waits is bounded by the number
//    of kinds, whatever the browser's speed.
//  * The map is kept as immutable snapshots (shared_ptr<const CellSet>). Each client holds the
//    snapshot it was last sent; take() sends the difference from it to the newest, so maps
//    skipped by a slow client cost nothing and only changed cells cross its socket, and a new
//    client starts from nothing (a reset with every cell).
//  * A client added later first gets the newest message of every broadcast kind.
//  * Thread-safe: post*() from the producer, take() from each client's sender, add/remove from
//    the server's threads. `wake` is called (outside the lock) after something was posted
//    for that client.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "station/map_cells.h"

namespace kestrel::station {

struct Outgoing {
  bool binary = false;
  std::string bytes;
};

class UpdateHub {
 public:
  using ClientId = uint64_t;
  explicit UpdateHub(size_t max_clients = 8) : max_clients_(max_clients) {}

  /// A new client; empty when max_clients are connected.
  std::optional<ClientId> add_client(std::function<void()> wake);
  void remove_client(ClientId id);
  size_t clients() const;

  /// To every client, and kept for clients that come later.
  void post(const std::string& kind, Outgoing message);
  /// To one client only (e.g. the answer to its command); not kept for others.
  void post_to(ClientId id, const std::string& kind, Outgoing message);
  /// A new map (null: no map).
  void post_map(std::shared_ptr<const CellSet> map);

  /// Everything waiting for `id` (the map difference last), and nothing waits any more.
  std::vector<Outgoing> take(ClientId id);

  struct Stats {
    int64_t posted = 0;   ///< messages posted, per client reached
    int64_t dropped = 0;  ///< replaced before they were taken
    int64_t taken = 0;
  };
  Stats stats() const;

 private:
  struct Client {
    std::function<void()> wake;
    std::map<std::string, Outgoing> waiting;
    std::shared_ptr<const CellSet> map_sent;  ///< what this client's page holds
  };
  void put(Client& c, const std::string& kind, Outgoing message);

  mutable std::mutex mutex_;
  size_t max_clients_;
  ClientId next_id_ = 1;
  std::map<ClientId, Client> clients_;
  std::map<std::string, Outgoing> latest_;  ///< per broadcast kind, for late clients
  std::shared_ptr<const CellSet> map_;
  Stats stats_;
};

}  // namespace kestrel::station
