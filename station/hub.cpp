#include "station/hub.h"

#include "station/wire.h"

namespace kestrel::station {

std::optional<UpdateHub::ClientId> UpdateHub::add_client(std::function<void()> wake) {
  std::function<void()> to_wake;
  ClientId id;
  {
    std::lock_guard lock(mutex_);
    if (clients_.size() >= max_clients_) return std::nullopt;
    id = next_id_++;
    Client& c = clients_[id];
    c.wake = std::move(wake);
    c.waiting = latest_;
    to_wake = c.wake;
  }
  if (to_wake) to_wake();
  return id;
}

void UpdateHub::remove_client(ClientId id) {
  std::lock_guard lock(mutex_);
  clients_.erase(id);
}

size_t UpdateHub::clients() const {
  std::lock_guard lock(mutex_);
  return clients_.size();
}

void UpdateHub::put(Client& c, const std::string& kind, Outgoing message) {
  ++stats_.posted;
  auto [it, inserted] = c.waiting.try_emplace(kind);
  if (!inserted) ++stats_.dropped;
  it->second = std::move(message);
}

void UpdateHub::post(const std::string& kind, Outgoing message) {
  std::vector<std::function<void()>> to_wake;
  {
    std::lock_guard lock(mutex_);
    for (auto& [id, c] : clients_) {
      put(c, kind, message);
      to_wake.push_back(c.wake);
    }
    latest_[kind] = std::move(message);
  }
  for (auto& w : to_wake)
    if (w) w();
}

void UpdateHub::post_to(ClientId id, const std::string& kind, Outgoing message) {
  std::function<void()> to_wake;
  {
    std::lock_guard lock(mutex_);
    const auto it = clients_.find(id);
    if (it == clients_.end()) return;
    put(it->second, kind, std::move(message));
    to_wake = it->second.wake;
  }
  if (to_wake) to_wake();
}

void UpdateHub::post_map(std::shared_ptr<const CellSet> map) {
  std::vector<std::function<void()>> to_wake;
  {
    std::lock_guard lock(mutex_);
    map_ = std::move(map);
    for (auto& [id, c] : clients_) to_wake.push_back(c.wake);
  }
  for (auto& w : to_wake)
    if (w) w();
}

std::vector<Outgoing> UpdateHub::take(ClientId id) {
  std::shared_ptr<const CellSet> before, after;
  std::vector<Outgoing> out;
  {
    std::lock_guard lock(mutex_);
    const auto it = clients_.find(id);
    if (it == clients_.end()) return out;
    Client& c = it->second;
    for (auto& [kind, message] : c.waiting) out.push_back(std::move(message));
    stats_.taken += static_cast<int64_t>(c.waiting.size());
    c.waiting.clear();
    if (map_ != c.map_sent) {
      before = c.map_sent;
      after = map_;
      c.map_sent = map_;
    }
  }
  // The difference is computed outside the lock: the snapshots are immutable.
  if (after) {
    const CellDiff diff = diff_cells(before ? *before : CellSet{}, *after);
    if (!diff.empty()) out.push_back({true, encode_map_diff(diff, after->size())});
  } else if (before) {
    CellDiff clear;
    clear.reset = true;
    out.push_back({true, encode_map_diff(clear, 0)});
  }
  return out;
}

UpdateHub::Stats UpdateHub::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace kestrel::station
