// Lock-step replay of a log (replayer.h): the log's events, filtered, through a
// LockstepDriver on a connection of its own.

#include <fmt/format.h>

#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <optional>

#include "common/transport/lcm_url.h"
#include "tools/replay/lockstep_driver.h"
#include "tools/replay/replayer.h"

namespace kestrel::replay {
namespace {

std::string event_label(int64_t index, const transport::LogEvent& e) {
  return "event #" + std::to_string(index) + " (" + e.channel + " at " +
         fmt::format("{:.6f}", 1e-6 * static_cast<double>(e.timestamp)) + " s)";
}

}  // namespace

ReplayReport replay_lockstep(transport::LogReader& log, const LockstepOptions& options,
                             const std::atomic<bool>& interrupted) {
  ReplayReport report;
  report.log_path = log.path();
  report.mode = "lock-step";
  const std::string url = transport::resolve_lcm_url(options.lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) throw NetworkUnavailable("cannot start LCM on '" + url + "'");
  LockstepDriver driver(
      lcm, [&lcm](int ms) { lcm.handleTimeout(ms); }, options.driver, [&interrupted] { return interrupted.load(); });
  if (!driver.begin()) {
    report.interrupted = true;
    return report;
  }
  report.processes = driver.processes();
  report.record_path = options.driver.record_path;
  // A channel that a discovered process publishes is not replayed from the log unless asked.
  EventFilter filter(options.selection, [&driver](const std::string& c) { return driver.publishers(c); });
  const auto wall_start = std::chrono::steady_clock::now();
  std::optional<int64_t> first_ts, previous_ts;
  int64_t index = -1;
  while (auto event = log.next()) {
    ++index;
    if (interrupted) {
      report.interrupted = true;
      break;
    }
    if (!filter.accept(*event)) continue;
    if (previous_ts && event->timestamp < *previous_ts) ++report.out_of_order;
    previous_ts = event->timestamp;
    if (!first_ts) first_ts = event->timestamp;
    report.data_s = 1e-6 * static_cast<double>(event->timestamp - *first_ts);
    if (!driver.publish(event->channel, event->data.data(), event->data.size(), event->timestamp,
                        event_label(index, *event))) {
      report.interrupted = true;
      break;
    }
    ++report.events_replayed;
    ++report.replayed[event->channel];
  }
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  report.skipped = filter.skipped_channels();
  report.outside_window = filter.outside_window();
  report.damage = log.damage_report();
  driver.close();
  report.recorded = driver.recorded();
  report.unannounced = driver.unannounced();
  report.latency = driver.latency();
  return report;
}

}  // namespace kestrel::replay
