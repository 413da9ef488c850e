#include "tools/launch/health.h"

#include <fmt/format.h>

#include <algorithm>

#include "common/cli.h"

namespace kestrel::launch {

std::string state_name(int8_t state) {
  switch (state) {
    case process_status_t::STATE_STARTING: return "STARTING";
    case process_status_t::STATE_RUNNING: return "RUNNING";
    case process_status_t::STATE_DEGRADED: return "DEGRADED";
    case process_status_t::STATE_STOPPING: return "STOPPING";
    case process_status_t::STATE_FAILED: return "FAILED";
    default: return "STATE " + std::to_string(state);
  }
}

void HealthBoard::started(const std::string& name, pid_t pid, Clock::time_point now, bool heartbeats) {
  if (!entries_.count(name)) order_.push_back(name);
  Entry& e = entries_[name];
  e = Entry{};
  e.pid = pid;
  e.since = now;
  e.launched = true;
  e.heartbeats = heartbeats;
}

void HealthBoard::ended(const std::string& name, const std::string& how, Clock::time_point now, double cpu_s) {
  auto it = entries_.find(name);
  if (it == entries_.end()) return;
  it->second.ended = how;
  it->second.ended_at = now;
  if (cpu_s >= 0.0) it->second.cpu_s = cpu_s;
}

void HealthBoard::cpu(const std::string& name, double cpu_s) {
  auto it = entries_.find(name);
  if (it != entries_.end() && !it->second.ended) it->second.cpu_s = cpu_s;
}

HealthBoard::Entry& HealthBoard::entry_of(pid_t pid, const std::string& name) {
  // By pid first: a launched process may call itself anything. One that has ended is still
  // the sender of its last heartbeat and counts, which often arrive after it was reaped (under
  // the name it went by, or its launch name): another process with its pid would call itself
  // something else.
  auto it = std::find_if(entries_.begin(), entries_.end(), [&](const auto& kv) {
    return kv.second.launched && kv.second.pid == pid && !kv.second.ended;
  });
  if (it == entries_.end())
    it = std::find_if(entries_.begin(), entries_.end(), [&](const auto& kv) {
      const Entry& e = kv.second;
      return e.launched && e.pid == pid && e.ended && (kv.first == name || (e.last && e.last->name == name));
    });
  if (it == entries_.end()) {
    const std::string key = name + " (not launched here)";
    if (!entries_.count(key)) order_.push_back(key);
    it = entries_.emplace(key, Entry{}).first;
    it->second.pid = pid;
  }
  return it->second;
}

void HealthBoard::heartbeat(const process_status_t& status, Clock::time_point now) {
  Entry& e = entry_of(status.pid, status.name);
  e.last = status;
  e.last_at = now;
}

void HealthBoard::rejections(const rejection_counts_t& counts) { entry_of(counts.pid, counts.name).rejections = counts; }

std::string HealthBoard::rejections_table() const {
  std::string s;
  for (const auto& name : order_) {
    const Entry& e = entries_.at(name);
    if (!e.rejections) continue;
    for (const rejection_reason_t& r : e.rejections->reasons) {
      // Any bytes a process (or a corrupt message) put there: escaped, as in table().
      s += fmt::format("{:<16} {:<18} {:>8}  {}\n{:<16} {:<18} {:>8}  last: {}\n", cli::printable(name),
                       cli::printable(r.channel), r.count, cli::printable(r.reason), "", "", "",
                       cli::printable(r.last));
    }
  }
  if (s.empty()) return s;
  return fmt::format("{:<16} {:<18} {:>8}  {}\n", "rejected by", "channel", "count", "reason") + s;
}

std::vector<HealthBoard::Row> HealthBoard::rows(Clock::time_point now) const {
  std::vector<Row> out;
  for (const auto& name : order_) {
    const Entry& e = entries_.at(name);
    Row r{name, e.pid, "", false, e.last, std::nullopt, std::nullopt};
    const double since_start = std::chrono::duration<double>(now - e.since).count();
    const double wall_s = std::chrono::duration<double>((e.ended ? e.ended_at : now) - e.since).count();
    if (e.launched && e.cpu_s >= 0.0) {
      r.cpu_s = e.cpu_s;
      if (wall_s > 0.0) r.cpu_percent = 100.0 * e.cpu_s / wall_s;
    }
    if (e.ended) {
      r.state = "ended: " + *e.ended;
    } else if (!e.last && !e.heartbeats) {
      r.state = "running";
      r.healthy = true;
    } else if (!e.last) {
      r.state = since_start > silent_after_s_ ? "no heartbeat" : "starting";
    } else {
      const double age = std::chrono::duration<double>(now - e.last_at).count();
      if (age > silent_after_s_) {
        r.state = fmt::format("silent {:.1f} s", age);
      } else {
        r.state = state_name(e.last->state);
        r.healthy = e.last->state == process_status_t::STATE_RUNNING;
      }
    }
    out.push_back(std::move(r));
  }
  return out;
}

std::string HealthBoard::table(Clock::time_point now) const {
  // The state goes last but one: "ended: killed by SIGSEGV" is long, the counters are not.
  std::string s = fmt::format("{:<16} {:>7} {:>9} {:>9} {:>8} {:>7} {:>6}  {:<16} {}\n", "process", "pid", "in",
                              "out", "rejected", "cpu s", "cpu %", "state", "message");
  for (const Row& r : rows(now)) {
    const auto& l = r.last;
    // A heartbeat's strings are any bytes a process (or a corrupt message) put there: the
    // terminal gets them escaped (found by fuzzing, fuzz/corpus/lcm-process_status_t/).
    s += fmt::format("{:<16} {:>7} {:>9} {:>9} {:>8} {:>7} {:>6}  {:<16} {}\n", cli::printable(r.name), r.pid,
                     l ? std::to_string(l->messages_in) : "-", l ? std::to_string(l->messages_out) : "-",
                     l ? std::to_string(l->messages_rejected) : "-",
                     r.cpu_s ? fmt::format("{:.2f}", *r.cpu_s) : "-",
                     r.cpu_percent ? fmt::format("{:.1f}", *r.cpu_percent) : "-", r.state,
                     l ? cli::printable(l->message) : "");
  }
  return s;
}

bool HealthBoard::all_running(Clock::time_point now) const {
  for (const Row& r : rows(now)) {
    const Entry& e = entries_.at(r.name);
    if (e.launched && !e.ended && !r.healthy) return false;
  }
  return true;
}

std::vector<std::string> HealthBoard::not_yet_heard() const {
  std::vector<std::string> out;
  for (const auto& name : order_) {
    const Entry& e = entries_.at(name);
    if (e.launched && !e.ended && e.heartbeats && !e.last) out.push_back(name);
  }
  return out;
}

}  // namespace kestrel::launch
