// kestrel-replay LOG: replays an LCM log into the running kestrel processes, in lock-step
// (deterministic, default) or timed like lcm-logplayer (--realtime, --speed). README.md
// explains the protocol, its guarantees and its limits.

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <iostream>

#include "common/interrupt.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/transport/log_file.h"
#include "tools/replay/replayer.h"

namespace {

}  // namespace

int main(int argc, char** argv) {
  using namespace kestrel;
  cli::App app("replay",
               "Replays an LCM log into the running kestrel processes. Default: deterministic "
               "lock-step (each event waits until every process has finished with it and with "
               "everything it caused). --realtime / --speed: timed, like lcm-logplayer.");
  std::string log_path;
  replay::LockstepOptions lockstep;
  bool realtime = false;
  double speed = 0.0;
  bool json = false;
  app.add_option("log", log_path, "LCM log to replay")->required();
  app.add_option("--lcm-url", lockstep.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--record", lockstep.driver.record_path,
                 "Lock-step: write every message the processes publish to this LCM log, in a "
                 "canonical order, stamped with the input event's time");
  app.add_option("--expect", lockstep.driver.expect, "Lock-step: processes that must take part (a,b,c)")
      ->delimiter(',');
  app.add_flag("--reset,!--no-reset", lockstep.driver.reset, "Lock-step: reset every process before the first event (default; --no-reset keeps their state)")
      ->capture_default_str();
  app.add_option("--ack-timeout", lockstep.driver.ack_timeout_s,
                 "Lock-step: seconds without progress on one event before giving up")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--discovery-timeout", lockstep.driver.discovery_timeout_s,
                 "Lock-step: seconds to wait for the --expect processes")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--settle", lockstep.driver.settle_s,
                 "Lock-step: seconds the set of processes must stay unchanged before starting")
      ->check(cli::Positive)
      ->capture_default_str();
  auto* realtime_flag = app.add_flag("--realtime", realtime, "Timed: at the log's own pace");
  app.add_option("--speed", speed, "Timed: log seconds per wall second")
      ->check(cli::Positive)
      ->excludes(realtime_flag);
  double max_gap_s = replay::TimedOptions{}.max_gap_s;
  app.add_option("--max-gap", max_gap_s,
                 "Timed: longest gap between two events that is waited out, in log seconds; a "
                 "longer one (a bad stamp) is played as this long and said once (0 = no cap)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--start", lockstep.selection.start_s, "Skip this many seconds of the log")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--duration", lockstep.selection.duration_s,
                 "Replay this many seconds of the log (0 = to its end)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--channels", lockstep.selection.channels_regex,
                 "Replay only channels matching this regex (whole name); also replays channels "
                 "that a live process publishes")
      ->check(CLI::Validator(replay::check_channel_regex, "REGEX"));
  bool control = false;
  app.add_flag("--control", control,
               "Timed (at --speed, else the log's pace): take play, pause, seek and speed from "
               "PLAYBACK_COMMAND (the ground station's transport bar), say the position on "
               "PLAYBACK_STATUS, and wait at the end of the log for a seek back, until Ctrl-C");
  app.add_flag("--json", json, "Print the report as JSON");

  return app.run(argc, argv, [&]() -> int {
    const bool timed = realtime || speed > 0.0 || control;
    if (timed && !lockstep.driver.record_path.empty())
      throw CLI::ValidationError("--record", "records only in lock-step mode (not with --realtime, --speed or --control)");
    const auto& interrupted = catch_interrupts();
    transport::LogReader log(log_path);
    replay::ReplayReport report;
    try {
      if (timed) {
        report = replay::replay_timed(
            log, {lockstep.lcm_url, speed > 0.0 ? speed : 1.0, lockstep.selection, max_gap_s, control}, interrupted);
      } else {
        report = replay::replay_lockstep(log, lockstep, interrupted);
      }
    } catch (const replay::NetworkUnavailable& e) {
      spdlog::error("{}", e.what());
      return kExitUnavailable;
    }
    if (!report.damage.empty()) spdlog::warn("{}", report.damage);
    std::cout << (json ? replay::to_json(report).dump(2) + "\n" : replay::format_text(report));
    return report.interrupted ? kExitInterrupted : kExitOk;
  });
}
