// Timed replay: the events are published at their log times divided by the speed, like
// lcm-logplayer, without waiting for anybody. An event stamped earlier than its predecessor
// goes out at once (and is counted) rather than making the replay wait or go back. A gap
// between consecutive events longer than `max_gap_s` (an event stamped an hour ahead) is
// played as `max_gap_s`, said once on stderr and counted, so one bad stamp cannot stall the
// replay; the events keep their stamps, only the waiting is shortened.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <thread>

#include "common/transport/lcm_url.h"
#include "tools/replay/replayer.h"

namespace kestrel::replay {
namespace {

// Microseconds from `earlier` to `later` (later >= earlier). Unsigned, because two int64
// stamps can lie further apart than an int64 holds; the difference always fits a uint64.
uint64_t span_us(int64_t earlier, int64_t later) {
  return static_cast<uint64_t>(later) - static_cast<uint64_t>(earlier);
}

// Seconds as microseconds, 0 for "no cap"; capped far beyond any log so that it converts.
uint64_t cap_us(double seconds) {
  if (!(seconds > 0.0)) return 0;
  return static_cast<uint64_t>(std::llround(std::min(seconds, 1e12) * 1e6));
}

}  // namespace

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
  const uint64_t max_gap_us = cap_us(o.max_gap_s);
  std::optional<int64_t> first_ts;
  int64_t latest_ts = 0;
  uint64_t paced_us = 0;  // log time since the first event, less what the cap cut out
  while (auto event = log.next()) {
    if (interrupted) break;
    if (!filter.accept(*event)) continue;
    if (!first_ts) first_ts = latest_ts = event->timestamp;
    if (event->timestamp < latest_ts && max_gap_us > 0 && span_us(event->timestamp, latest_ts) > max_gap_us) {
      // A jump back beyond the cap: the stamp before it was the bad one (or the clock was
      // reset). Pacing resumes from this event, or every later one would be "out of order"
      // and the rest of the log would go out in one burst.
      if (report.gaps_capped == 0)
        spdlog::warn("{}: the log jumps {:.3f} s back before an event on {}; pacing resumes from it "
                     "(--max-gap {:g} s; 0 = no cap)",
                     log.path(), 1e-6 * static_cast<double>(span_us(event->timestamp, latest_ts)),
                     event->channel, o.max_gap_s);
      ++report.gaps_capped;
      latest_ts = event->timestamp;
    } else if (event->timestamp < latest_ts) {
      ++report.out_of_order;
    } else {
      uint64_t gap_us = span_us(latest_ts, event->timestamp);
      if (max_gap_us > 0 && gap_us > max_gap_us) {
        if (report.gaps_capped == 0)
          spdlog::warn("{}: a gap of {:.3f} s before an event on {} is played as {:g} s "
                       "(--max-gap; 0 = no cap); so is every later gap over {:g} s",
                       log.path(), 1e-6 * static_cast<double>(gap_us), event->channel, o.max_gap_s,
                       o.max_gap_s);
        ++report.gaps_capped;
        report.gap_time_cut_s += 1e-6 * static_cast<double>(gap_us - max_gap_us);
        gap_us = max_gap_us;
      }
      paced_us += gap_us;
      latest_ts = event->timestamp;
      // Bounded so that it converts to the clock's nanoseconds (a log without a cap may
      // span more than the clock holds); 30 years is still "wait".
      const double wait_s = std::min(1e-6 * static_cast<double>(paced_us) / o.speed, 1e9);
      const auto due = wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_s));
      // Sleep in short steps so that Ctrl-C is honoured promptly.
      while (!interrupted && Clock::now() < due)
        std::this_thread::sleep_for(std::min<Clock::duration>(due - Clock::now(), std::chrono::milliseconds(50)));
      if (interrupted) break;
      report.data_s = 1e-6 * static_cast<double>(span_us(*first_ts, latest_ts));
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
