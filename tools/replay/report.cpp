#include "tools/replay/report.h"

#include <fmt/format.h>

namespace kestrel::replay {
namespace {

int64_t sum(const std::map<std::string, int64_t>& counts) {
  int64_t n = 0;
  for (const auto& [channel, count] : counts) n += count;
  return n;
}

}  // namespace

std::string format_text(const ReplayReport& r) {
  std::string s = fmt::format("{} replay of {}{}\n", r.mode, r.log_path,
                              r.interrupted ? " (INTERRUPTED)" : "");
  for (const auto& p : r.processes) s += fmt::format("  process {}\n", p);
  s += fmt::format("replayed {} events: {:.3f} s of log time in {:.3f} s wall ({:.1f}x)\n",
                   r.events_replayed, r.data_s, r.wall_s, r.speedup());
  for (const auto& [channel, n] : r.replayed) s += fmt::format("  {:<24} {:>8}\n", channel, n);
  if (!r.skipped.empty()) {
    s += "skipped channels:\n";
    for (const auto& [channel, k] : r.skipped)
      s += fmt::format("  {:<24} {:>8}  {}\n", channel, k.events, k.reason);
  }
  if (r.outside_window > 0)
    s += fmt::format("outside --start/--duration: {} events\n", r.outside_window);
  if (r.out_of_order > 0)
    s += fmt::format("out of time order: {} events (published without waiting)\n", r.out_of_order);
  if (r.gaps_capped > 0)
    s += fmt::format("gaps over --max-gap: {}, {:.3f} s of log time not waited for\n", r.gaps_capped,
                     r.gap_time_cut_s);
  if (!r.damage.empty()) s += r.damage + " (the intact events were replayed)\n";
  if (!r.record_path.empty()) {
    s += fmt::format("recorded {} messages to {}\n", sum(r.recorded), r.record_path);
    for (const auto& [channel, n] : r.recorded) s += fmt::format("  {:<24} {:>8}\n", channel, n);
    if (r.unannounced > 0)
      s += fmt::format("  {} of them were published outside any handler (not lock-step)\n",
                       r.unannounced);
  }
  if (!r.latency.empty())
    s += format_latency(r.latency);
  return s;
}

nlohmann::json to_json(const ReplayReport& r) {
  nlohmann::json skipped = nlohmann::json::object();
  for (const auto& [channel, k] : r.skipped)
    skipped[channel] = {{"events", k.events}, {"reason", k.reason}};
  nlohmann::json j = {{"log", r.log_path},
                      {"mode", r.mode},
                      {"processes", r.processes},
                      {"events_replayed", r.events_replayed},
                      {"replayed", r.replayed},
                      {"skipped", skipped},
                      {"outside_window", r.outside_window},
                      {"out_of_order", r.out_of_order},
                      {"gaps_capped", r.gaps_capped},
                      {"gap_time_cut_s", r.gap_time_cut_s},
                      {"damage", r.damage},
                      {"data_s", r.data_s},
                      {"wall_s", r.wall_s},
                      {"speedup", r.speedup()},
                      {"interrupted", r.interrupted}};
  if (!r.record_path.empty()) {
    j["record"] = {{"path", r.record_path},
                   {"messages", sum(r.recorded)},
                   {"channels", r.recorded},
                   {"unannounced", r.unannounced}};
  }
  if (!r.latency.empty()) {
    nlohmann::json rows = nlohmann::json::array();
    for (const auto& l : r.latency)
      rows.push_back({{"input", l.input}, {"process", l.process}, {"handled", l.handled}, {"events", l.count},
                      {"median_ms", l.median_ms}, {"p95_ms", l.p95_ms}, {"max_ms", l.max_ms}});
    j["latency"] = rows;
  }
  return j;
}

}  // namespace kestrel::replay
