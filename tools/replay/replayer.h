#pragma once
// Replaying an LCM log into running kestrel processes, in one of two modes (README.md):
//
//  * lock-step (replay_lockstep): deterministic. Finds the processes from their heartbeats,
//    optionally resets them, then publishes one event at a time and waits until every
//    process that consumes it, and everything they publish in turn, has been acknowledged
//    (AckLedger). Optionally records every output in a canonical order (OutputRecorder).
//  * timed (replay_timed): like lcm-logplayer, paced on the events' timestamps, with no
//    wait between two events longer than the gap cap.
//
// Both read the log with LogReader, so a damaged log is replayed up to (and beyond) the
// damage, which the report states.

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/transport/log_file.h"
#include "tools/replay/event_filter.h"
#include "tools/replay/lockstep_driver.h"
#include "tools/replay/report.h"

namespace kestrel::replay {

/// LCM could not be started on the URL.
class NetworkUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LockstepOptions {
  std::string lcm_url;  ///< "" = $LCM_DEFAULT_URL or kestrel's default
  DriverOptions driver;  ///< discovery, reset, timeouts, recording (a replay's set is fixed)
  SelectionOptions selection;
};

struct TimedOptions {
  std::string lcm_url;
  double speed = 1.0;  ///< log seconds per wall second
  SelectionOptions selection;
  /// Longest gap between consecutive events that is waited out, in log seconds (0 = no cap).
  /// A longer gap (an event stamped an hour ahead) is played as this long, and said once.
  double max_gap_s = 5.0;
  /// Take play, pause, seek and speed from PLAYBACK_COMMAND and say the position on
  /// PLAYBACK_STATUS (PlaybackClock); at the end of the log, wait for a seek back (until
  /// interrupted) instead of ending.
  bool control = false;
};

/// Throws PeerError, NetworkUnavailable, InputError (recording file). Returns early with
/// report.interrupted set once `interrupted` becomes true; END is always sent.
ReplayReport replay_lockstep(transport::LogReader& log, const LockstepOptions& options,
                             const std::atomic<bool>& interrupted);

/// Throws NetworkUnavailable.
ReplayReport replay_timed(transport::LogReader& log, const TimedOptions& options,
                          const std::atomic<bool>& interrupted);

}  // namespace kestrel::replay
