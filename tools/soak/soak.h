#pragma once
// What `kestrel soak` measures and concludes, LCM-free: the samples taken while the whole
// system flies (each process's resident memory and CPU time, and the flight's progress), and
// per process its memory after the warm-up and at the end, its growth over the last two
// thirds of the run (a least-squares line, MB per 10 simulated minutes) and the verdict, flat
// or growing, against a stated bound. Written as CSV, Markdown and JSON.
//
// Time is the simulator's (seconds of simulated flight since its start): in lock-step the
// processes handle the same frames at any pace, so a figure per simulated minute is the same
// on a loaded machine, where one per wall minute is not.

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::soak {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One process, once.
struct ProcessSample {
  double wall_s = 0.0;   ///< since the soak began
  double sim_s = 0.0;    ///< simulated time reached when it was taken
  std::string process;   ///< the launch's name: sim, vo, estimator, follow, slam, mapper
  int pid = -1;
  double rss_mb = 0.0;   ///< resident set (VmRSS), 10^6 bytes
  double anon_mb = 0.0;  ///< its anonymous part (RssAnon: the heap, where a leak shows)
  double cpu_s = 0.0;    ///< CPU time (user + system) since the process started
  int64_t frames = 0;    ///< camera frames the VO had measured by then (the system's frame count)
};

/// The flight, once per round of samples.
struct ProgressSample {
  double wall_s = 0.0;
  double sim_s = 0.0;
  int64_t frames = 0;          ///< VO_UPDATEs heard (by their frame numbers)
  int64_t vo_failures = 0;     ///< ... of them not OK (no motion measured: a blank wall, too few matches)
  double vo_elapsed_ms = kNaN;  ///< the VO's own time per frame (vo_update_t.elapsed_ms), mean since the last round
  double distance_m = 0.0;     ///< flown by the truth
  int64_t keyframes = 0;       ///< in SLAM's latest graph
  int64_t corrections = 0;     ///< SLAM_CORRECTIONs heard
};

struct Criteria {
  double run_s = 1800.0;              ///< the simulated time asked for
  double warmup_s = 300.0;            ///< the memory "after warm-up" is the first sample from here
  double flat_mb_per_10min = 2.0;     ///< flat: grows by less than this
};

/// The least-squares line y = a + b x; b NaN with fewer than two distinct x.
struct Line {
  double intercept = kNaN;
  double slope = kNaN;
};
Line fit_line(const std::vector<double>& x, const std::vector<double>& y);

/// CPU time per camera frame between two samples of one process, ms (NaN without frames between).
double cpu_ms_per_frame(const ProcessSample& from, const ProcessSample& to);

struct ProcessSummary {
  std::string process;
  size_t samples = 0;
  bool died = false;               ///< it ended before the flight did (`died_how` says how)
  std::string died_how;
  double warmup_at_s = kNaN;       ///< the simulated time of the warm-up sample
  double rss_warmup_mb = kNaN;
  double end_at_s = kNaN;          ///< ... of the last sample
  double rss_end_mb = kNaN;
  double rss_peak_mb = kNaN;
  double anon_warmup_mb = kNaN;
  double anon_end_mb = kNaN;
  double fit_from_s = kNaN;        ///< the growth is fitted over [fit_from_s, end_at_s]
  size_t fit_samples = 0;
  double growth_mb_per_10min = kNaN;       ///< RSS, per 10 simulated minutes
  double anon_growth_mb_per_10min = kNaN;  ///< RssAnon, same
  double cpu_ms_per_frame_early = kNaN;  ///< over the first third after the warm-up
  double cpu_ms_per_frame_late = kNaN;   ///< over the last third of the run
  double cpu_ms_per_frame_all = kNaN;    ///< from the warm-up to the end
  std::string verdict;  ///< "flat", "grows", "died", "too short" (fewer than 3 samples to fit)
};

struct Summary {
  Criteria criteria;
  double sim_s = 0.0;        ///< reached
  double wall_s = 0.0;
  int64_t frames = 0;
  int64_t vo_failures = 0;
  double distance_m = 0.0;
  int64_t keyframes = 0;
  int64_t corrections = 0;
  double wall_ms_per_frame = kNaN;    ///< the whole system's pace in lock-step, warm-up to end
  double vo_elapsed_ms = kNaN;        ///< mean of the rounds from the warm-up on
  std::vector<ProcessSummary> processes;  ///< in the order they were first sampled
  /// Every process was sampled at least twice and the simulated time moved: something to read.
  bool usable() const;
  /// Every process flat.
  bool all_flat() const;
};

/// The summary of a run. `died` names each process that ended early, with how.
Summary summarise(const std::vector<ProcessSample>& samples, const std::vector<ProgressSample>& progress,
                  const Criteria& criteria, const std::vector<std::pair<std::string, std::string>>& died = {});

/// samples.csv: wall_s,sim_s,process,pid,rss_MB,anon_MB,cpu_s,frames,cpu_ms_per_frame (the
/// last since the process's previous sample; empty for its first).
std::string samples_csv(const std::vector<ProcessSample>& samples);
/// progress.csv: wall_s,sim_s,frames,vo_failures,vo_elapsed_ms,wall_ms_per_frame,distance_m,keyframes,corrections.
std::string progress_csv(const std::vector<ProgressSample>& progress);

/// report.md: what was flown, then a table per process; `heading` describes the run (world,
/// route, command), `failure` is why the flight stopped early ("" when it did not).
std::string markdown(const Summary& s, const std::string& heading, const std::string& failure);
nlohmann::json to_json(const Summary& s, const std::string& failure);

}  // namespace kestrel::soak
