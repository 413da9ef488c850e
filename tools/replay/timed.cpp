// Timed replay: the events are published at their log times divided by the speed, like
// lcm-logplayer, without waiting for anybody. An event stamped earlier than its predecessor
// goes out at once (and is counted) rather than making the replay wait or go back.

#include <fmt/format.h>

#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <thread>

#include "common/transport/lcm_url.h"
#include "tools/replay/replayer.h"

namespace kestrel::replay {

ReplayReport replay_timed(transport::LogReader& log, const TimedOptions& o,
                          const std::atomic<bool>& interrupted) {
  using Clock = std::chrono::steady_clock;
  const std::string url = transport::resolve_lcm_url(o.lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) throw NetworkUnavailable("cannot start LCM on '" + url + "'");

  ReplayReport report;
  report.log_path = log.path();
  report.mode = fmt::format("timed (speed {:g})", o.speed);
  EventFilter filter(o.selection, nullptr);
  const Clock::time_point wall_start = Clock::now();
  std::optional<int64_t> first_ts;
  int64_t latest_ts = 0;
  while (auto event = log.next()) {
    if (interrupted) break;
    if (!filter.accept(*event)) continue;
    if (!first_ts) first_ts = latest_ts = event->timestamp;
    if (event->timestamp < latest_ts) {
      ++report.out_of_order;
    } else {
      latest_ts = event->timestamp;
      const auto due = wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                        1e-6 * static_cast<double>(latest_ts - *first_ts) / o.speed));
      // Sleep in short steps so that Ctrl-C is honoured promptly.
      while (!interrupted && Clock::now() < due)
        std::this_thread::sleep_for(std::min<Clock::duration>(due - Clock::now(), std::chrono::milliseconds(50)));
      if (interrupted) break;
      report.data_s = 1e-6 * static_cast<double>(latest_ts - *first_ts);
    }
    lcm.publish(event->channel, event->data.data(), static_cast<unsigned>(event->data.size()));
    ++report.events_replayed;
    ++report.replayed[event->channel];
  }
  report.interrupted = interrupted;
  report.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  report.skipped = filter.skipped_channels();
  report.outside_window = filter.outside_window();
  report.damage = log.damage_report();
  return report;
}

}  // namespace kestrel::replay
