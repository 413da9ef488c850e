#include "tools/replay/process_table.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/transport/channels.h"

namespace kestrel::replay {
namespace {

std::vector<std::string> data_channels(const std::vector<std::string>& channels) {
  std::vector<std::string> out;
  for (const auto& c : channels)
    if (!is_protocol_channel(c)) out.push_back(c);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// A table cell: the items, or "-" for none.
std::string cell(const std::vector<std::string>& items) {
  return items.empty() ? "-" : fmt::format("{}", fmt::join(items, ", "));
}

}  // namespace

bool is_protocol_channel(const std::string& channel) {
  return channel == channel::kProcessStatus || channel == channel::kProcessRejections ||
         channel == channel::kReplayControl || channel == channel::kReplayAck ||
         // A review's transport: replayed, a recorded command would drive the replay itself.
         channel == channel::kPlaybackCommand || channel == channel::kPlaybackStatus;
}

bool ProcessTable::update(const kestrel::process_status_t& status, double now_s) {
  auto [it, added] = processes_.try_emplace(status.name);
  ProcessInfo& p = it->second;
  auto subscriptions = data_channels(status.subscriptions);
  auto publications = data_channels(status.publications);
  const bool changed = added || subscriptions != p.subscriptions || publications != p.publications;
  p.name = status.name;
  p.pid = status.pid;
  p.state = status.state;
  p.subscriptions = std::move(subscriptions);
  p.publications = std::move(publications);
  p.last_heard_s = now_s;
  p.pids_heard_s[status.pid] = now_s;
  return changed;
}

std::vector<std::string> ProcessTable::missing(const std::vector<std::string>& expected) const {
  std::vector<std::string> out;
  for (const auto& name : expected)
    if (!contains(name)) out.push_back(name);
  return out;
}

std::vector<std::string> ProcessTable::conflicts(double now_s) const {
  std::vector<std::string> out;
  for (const auto& [name, p] : processes_) {
    std::vector<std::string> pids;
    for (const auto& [pid, heard_s] : p.pids_heard_s)
      if (now_s - heard_s <= conflict_window_s_) pids.push_back(std::to_string(pid));
    if (pids.size() > 1) out.push_back(fmt::format("{} (pids {})", name, fmt::join(pids, ", ")));
  }
  return out;
}

ConsumerMap ProcessTable::consumers() const {
  ConsumerMap map;
  for (const auto& [name, p] : processes_)  // by name, so each list comes out sorted
    for (const auto& channel : p.subscriptions) map[channel].push_back(name);
  return map;
}

std::vector<std::string> ProcessTable::publishers(const std::string& channel) const {
  std::vector<std::string> out;
  for (const auto& [name, p] : processes_)
    if (std::binary_search(p.publications.begin(), p.publications.end(), channel))
      out.push_back(name);
  return out;
}

std::vector<std::string> describe(const ProcessTable& table) {
  std::vector<std::string> lines;
  for (const auto& [name, p] : table.processes())
    lines.push_back(name + " (pid " + std::to_string(p.pid) + "): " + cell(p.subscriptions) +
                    " -> " + cell(p.publications));
  return lines;
}

}  // namespace kestrel::replay
