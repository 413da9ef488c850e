// Timed replay: the events are published at their log times divided by the speed, like
// lcm-logplayer, without waiting for anybody. An event stamped earlier than its predecessor
// goes out at once (and is counted) rather than making the replay wait or go back. A gap
// between consecutive events longer than `max_gap_s` (an event stamped an hour ahead) is
// played as `max_gap_s`, said once on stderr and counted, so one bad stamp cannot stall the
// replay; the events keep their stamps, only the waiting is shortened.
//
// With `control` (a recorded flight under review) the PlaybackClock also takes play, pause,
// seek and speed from PLAYBACK_COMMAND, says where it is on PLAYBACK_STATUS, and waits at the
// end of the log for a seek back instead of ending (until interrupted).

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/message.h"
#include "kestrel/playback_command_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "tools/replay/playback_clock.h"
#include "tools/replay/seek_index.h"
#include "tools/replay/replayer.h"

namespace kestrel::replay {
namespace {

using Clock = std::chrono::steady_clock;

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

// The first and last log time of the events `filter` replays, and the seek index: one pass
// over the log, the filter seeing each event once.
std::optional<std::pair<int64_t, int64_t>> window_of(transport::LogReader& log, EventFilter& filter, SeekIndex& index) {
  std::optional<std::pair<int64_t, int64_t>> window;
  while (auto event = log.next()) {
    const bool replayed = filter.accept(*event);
    index.add_event(event->offset, event->timestamp, event->channel, replayed);
    if (!replayed) continue;
    if (!window) window = std::pair{event->timestamp, event->timestamp};
    window->first = std::min(window->first, event->timestamp);
    window->second = std::max(window->second, event->timestamp);
  }
  log.rewind();
  return window;
}

// The transport of a controlled replay: the commands heard, and the status said.
class Transport {
 public:
  Transport(lcm::LCM& lcm, std::string log_name, std::pair<int64_t, int64_t> window)
      : lcm_(lcm), log_name_(std::move(log_name)), window_(window) {
    lcm_.subscribe(channel::kPlaybackCommand, &Transport::on_command, this);
  }

  // Waits for commands until `until` (at most 50 ms at a time, so that an interrupt is seen);
  // true if one arrived.
  bool wait(Clock::time_point until) {
    // Rounded up: a wait of under a millisecond is one, not a spin on handleTimeout(0).
    const auto left_us = std::chrono::duration_cast<std::chrono::microseconds>(until - Clock::now()).count();
    const int ms = static_cast<int>(std::clamp<int64_t>((left_us + 999) / 1000, 0, 50));
    lcm_.handleTimeout(ms);
    return !commands_.empty();
  }
  std::optional<playback_command_t> take() {
    if (commands_.empty()) return std::nullopt;
    playback_command_t c = commands_.front();
    commands_.pop_front();
    return c;
  }
  // Publishes the status now if `force`, else at most 4 times a second.
  void say(const PlaybackClock& clock, int64_t position_us, bool at_end, int seeks, int64_t last_request_id,
           bool force) {
    const Clock::time_point now = Clock::now();
    if (!force && now < next_status_) return;
    next_status_ = now + std::chrono::milliseconds(250);
    playback_status_t s{};
    s.utime = position_us;
    s.start_utime = window_.first;
    s.end_utime = window_.second;
    s.speed = clock.speed();
    s.paused = clock.paused() || at_end;
    s.at_end = at_end;
    s.seeks = seeks;
    s.last_request_id = last_request_id;
    s.log_name = log_name_;
    lcm_.publish(channel::kPlaybackStatus, &s);
  }
  std::pair<int64_t, int64_t> window() const { return window_; }

 private:
  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    try {
      const auto c = transport::decode_message<playback_command_t>(rbuf->data, rbuf->data_size, channel);
      if (seen_.count(c.request_id)) return;  // a sender's repeat
      seen_.insert(c.request_id);
      if (seen_.size() > 1024) seen_.erase(seen_.begin());
      commands_.push_back(c);
    } catch (const std::exception& e) {
      spdlog::warn("{}", e.what());
    }
  }
  lcm::LCM& lcm_;
  std::string log_name_;
  std::pair<int64_t, int64_t> window_;
  std::deque<playback_command_t> commands_;
  std::set<int64_t> seen_;
  Clock::time_point next_status_{};
};

}  // namespace

ReplayReport replay_timed(transport::LogReader& log, const TimedOptions& o,
                          const std::atomic<bool>& interrupted) {
  const std::string url = transport::resolve_lcm_url(o.lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) throw NetworkUnavailable("cannot start LCM on '" + url + "'");

  ReplayReport report;
  report.log_path = log.path();
  report.mode = fmt::format("timed (speed {:g}{})", o.speed, o.control ? ", controlled" : "");
  std::optional<Transport> control;
  SeekIndex index;
  // Under control the report's skip counts are the first pass's: a seek reads parts again.
  std::optional<EventFilter> first_pass;
  if (o.control) {
    first_pass.emplace(o.selection, nullptr);
    const auto window = window_of(log, *first_pass, index);
    if (!window) spdlog::warn("{}: no event to replay (--channels, --start, --duration): nothing to control", log.path());
    if (window) {
      control.emplace(lcm, std::filesystem::path(log.path()).filename().string(), *window);
      spdlog::info("{}: {:.1f} s of log; play, pause, seek and speed on {}, the position on {}", log.path(),
                   1e-6 * static_cast<double>(span_us(window->first, window->second)), channel::kPlaybackCommand,
                   channel::kPlaybackStatus);
    }
  }
  auto filter = std::make_unique<EventFilter>(o.selection, nullptr);
  const Clock::time_point wall_start = Clock::now();
  const auto now_s = [&] { return std::chrono::duration<double>(Clock::now() - wall_start).count(); };
  const uint64_t max_gap_us = cap_us(o.max_gap_s);
  std::optional<PlaybackClock> clock;
  std::optional<int64_t> first_ts, seek_to;
  int64_t latest_ts = 0, last_request_id = 0;
  int64_t published_ts = 0;  // the position a status says: the last event published (or the seek's target)
  int seeks = 0;
  bool at_end = false;
  std::optional<transport::LogEvent> pending;  // read while seeking: the first event at the new position

  // Acts on the commands that arrived; a seek is left in seek_to for the loop to carry out.
  const auto act = [&] {
    while (auto c = control->take()) {
      last_request_id = c->request_id;
      const double now = now_s();
      try {
        switch (c->command) {
          case playback_command_t::COMMAND_PLAY: clock->play(now); break;
          case playback_command_t::COMMAND_PAUSE: clock->pause(now); break;
          case playback_command_t::COMMAND_SPEED: clock->set_speed(c->speed, now); break;
          case playback_command_t::COMMAND_SEEK:
            seek_to = std::clamp(c->seek_utime, control->window().first, control->window().second);
            break;
          default: spdlog::warn("playback command {} unknown; ignored", static_cast<int>(c->command));
        }
      } catch (const std::invalid_argument& e) {
        spdlog::warn("{}; ignored", e.what());
      }
      control->say(*clock, seek_to.value_or(published_ts), at_end, seeks, last_request_id, true);
    }
  };

  while (!interrupted) {
    if (seek_to) {
      // Publish for each channel the last event before the new position (the map, graph,
      // plan and image of that moment), then play on. The index's checkpoint before it names
      // them up to there; the log is read from there to the position (seek_index.h).
      const Checkpoint& from = index.start_for(*seek_to);
      filter = std::make_unique<EventFilter>(o.selection, nullptr, index.first_timestamp());
      std::map<std::string, transport::LogEvent> last_of;
      for (const auto& [channel, offset] : from.last_offset_of) {
        log.seek(offset);
        auto e = log.next();
        if (!e || e->offset != offset || e->channel != channel)
          throw InputError(log.path() + ": changed while it was replayed (no " + channel + " event at byte " +
                           std::to_string(offset) + " any more)");
        last_of[channel] = std::move(*e);
      }
      log.seek(from.offset);
      std::optional<transport::LogEvent> next_event;
      while (!interrupted) {
        auto event = log.next();
        if (!event) break;
        if (!filter->accept(*event)) continue;
        if (event->timestamp >= *seek_to) {
          next_event = std::move(event);
          break;
        }
        last_of[event->channel] = std::move(*event);
      }
      if (interrupted) break;
      clock->seek(*seek_to, now_s());
      latest_ts = published_ts = *seek_to;
      seek_to.reset();
      ++seeks;
      at_end = !next_event;
      // The status first: a viewer forgets the flight it drew on a new seek count, then
      // draws the moment from what follows.
      control->say(*clock, published_ts, at_end, seeks, last_request_id, true);
      std::vector<const transport::LogEvent*> moment;
      for (const auto& [channel, event] : last_of) moment.push_back(&event);
      std::sort(moment.begin(), moment.end(), [](const auto* a, const auto* b) { return a->timestamp < b->timestamp; });
      for (const transport::LogEvent* e : moment)
        lcm.publish(e->channel, e->data.data(), static_cast<unsigned>(e->data.size()));
      pending = std::move(next_event);  // published below as any other event, paced from the new position
    }
    std::optional<transport::LogEvent> event = pending ? std::move(pending) : log.next();
    pending.reset();
    if (!event) {
      if (!control) break;
      // The end: wait there for a seek back (or an interrupt).
      at_end = true;
      while (!interrupted && !seek_to) {
        control->wait(Clock::now() + std::chrono::milliseconds(50));
        act();
        control->say(*clock, published_ts, at_end, seeks, last_request_id, false);
      }
      at_end = false;
      continue;
    }
    if (!filter->accept(*event)) continue;
    if (!first_ts) {
      first_ts = latest_ts = event->timestamp;
      clock.emplace(o.speed, event->timestamp, now_s());
    }
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
      clock->seek(event->timestamp, now_s());
    } else if (event->timestamp < latest_ts) {
      ++report.out_of_order;
    } else {
      const uint64_t gap_us = span_us(latest_ts, event->timestamp);
      if (max_gap_us > 0 && gap_us > max_gap_us) {
        if (report.gaps_capped == 0)
          spdlog::warn("{}: a gap of {:.3f} s before an event on {} is played as {:g} s "
                       "(--max-gap; 0 = no cap); so is every later gap over {:g} s",
                       log.path(), 1e-6 * static_cast<double>(gap_us), event->channel, o.max_gap_s,
                       o.max_gap_s);
        ++report.gaps_capped;
        report.gap_time_cut_s += 1e-6 * static_cast<double>(gap_us - max_gap_us);
        // At most an int64's half: two stamps may lie further apart than an int64 holds.
        clock->skip(static_cast<int64_t>(std::min<uint64_t>(gap_us - max_gap_us, uint64_t{1} << 62)));
      }
      latest_ts = event->timestamp;
      if (control) {
        // Commands are heard even when the replay is behind (every event already due).
        control->wait(Clock::now());
        act();
        if (seek_to) continue;
        control->say(*clock, published_ts, false, seeks, last_request_id, false);
      }
      // Wait until it is due, in short steps so that Ctrl-C (and a command) is honoured
      // promptly; bounded so that it converts (a log without a cap may span more than the
      // clock holds: 30 years is still "wait").
      while (!interrupted) {
        const double due = std::min(clock->due_s(event->timestamp), now_s() + 1e9);
        const auto until = wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(due));
        if (Clock::now() >= until) break;
        if (control) {
          control->wait(until);
          act();
          if (seek_to) break;
          control->say(*clock, published_ts, false, seeks, last_request_id, false);
        } else {
          std::this_thread::sleep_for(std::min<Clock::duration>(until - Clock::now(), std::chrono::milliseconds(50)));
        }
      }
      if (interrupted) break;
      if (seek_to) continue;  // the event is read again after the seek, if it lies beyond it
      report.data_s = 1e-6 * static_cast<double>(span_us(*first_ts, latest_ts));
    }
    lcm.publish(event->channel, event->data.data(), static_cast<unsigned>(event->data.size()));
    published_ts = event->timestamp;
    ++report.events_replayed;
    ++report.replayed[event->channel];
  }
  report.interrupted = interrupted;
  report.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  const EventFilter& counted = first_pass ? *first_pass : *filter;
  report.skipped = counted.skipped_channels();
  report.outside_window = counted.outside_window();
  report.damage = log.damage_report();
  return report;
}

}  // namespace kestrel::replay
