#pragma once
// What a replay did, for the person or script that ran it: events replayed per channel,
// what was skipped and why, damage found in the log, timing, and what was recorded.
// Printed as text, or as JSON with --json.

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tools/replay/event_filter.h"
#include "tools/replay/latency.h"

namespace kestrel::replay {

struct ReplayReport {
  std::string log_path;
  std::string mode;                      ///< "lock-step" or "timed (speed x)"
  std::vector<std::string> processes;    ///< lock-step: the discovered processes
  int64_t events_replayed = 0;
  std::map<std::string, int64_t> replayed;            ///< channel -> events
  std::map<std::string, SkippedChannel> skipped;      ///< channel -> events, reason
  int64_t outside_window = 0;                         ///< left out by --start/--duration
  int64_t out_of_order = 0;                           ///< events stamped before their predecessor
  int64_t gaps_capped = 0;      ///< timed: gaps between events played shorter (--max-gap)
  double gap_time_cut_s = 0.0;  ///< timed: log seconds those gaps were shortened by, in total
  std::string damage;                                 ///< LogReader::damage_report()
  double data_s = 0.0;                                ///< log time spanned by the replayed events
  double wall_s = 0.0;
  std::string record_path;
  std::map<std::string, int64_t> recorded;            ///< channel -> messages
  int64_t unannounced = 0;  ///< outputs received that no acknowledgement announced
  std::vector<LatencyRow> latency;  ///< lock-step: publication -> each acknowledgement (wall clock)
  bool interrupted = false;

  double speedup() const { return wall_s > 0.0 ? data_s / wall_s : 0.0; }
};

std::string format_text(const ReplayReport& report);
nlohmann::json to_json(const ReplayReport& report);

}  // namespace kestrel::replay
