#pragma once
// How long each process took with each input event, measured by the lock-step driver: from
// the moment it published an event to the moment each process acknowledged an input of that
// event (the event itself or a message the event caused). A process acknowledges after its
// handler has returned, so the time includes what the handler published. The estimator's
// acknowledgement of a VO_UPDATE in a CAMERA_RGBD event is when the frame was fused: running
// on the VO alone it has then published the STATE that includes the frame; with an IMU that
// STATE goes out with the next IMU sample (at most one IMU period later in flight; in
// lock-step, the next event).
//
// Wall-clock times, so they depend on the machine and its load (the recording does not). The
// LCM hops are in every figure: about 0.1 ms for a small message, milliseconds for a camera
// frame (and the driver, when recording, receives its own frame back too).
//
// Rows per (input, process, handled channel): the first acknowledgement of that channel in an
// event. And per (input, process) a row whose handled channel is kAll: the process's last
// acknowledgement in the event, i.e. when it was done with the event and all it caused.
//
// Invariants: a row's quantiles are of at least one sample; acknowledgements outside an
// event (before the first, or after end_event) are not counted; rows are ordered by input
// channel, then by median.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace kestrel::replay {

struct LatencyRow {
  std::string input;    ///< the channel the driver published
  std::string process;  ///< who acknowledged
  std::string handled;  ///< what it acknowledged: the input or a message it caused
  int64_t count = 0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double max_ms = 0.0;
};

/// The samples of one row, bounded: exact up to kExactSamples, then folded into log-spaced
/// bins 1 % wide from 1 us to 1000 s (quantiles then to 1 %; the count and the maximum stay
/// exact). A driver that runs for hours keeps a few kilobytes per row: keeping every sample
/// grew the simulator by 31 MB in a 30-minute soak (tools/soak).
class LatencySamples {
 public:
  static constexpr size_t kExactSamples = 4096;
  void add(double ms);
  int64_t count() const { return count_; }
  double max() const { return max_; }
  /// Nearest-rank quantile, as replay::quantile() while exact; NaN when empty.
  double quantile(double q) const;

 private:
  static size_t bin_of(double ms);
  static double value_of(size_t bin);
  std::vector<double> exact_;
  std::vector<int64_t> bins_;  ///< empty while the samples are exact
  int64_t count_ = 0;
  double max_ = 0.0;
};

class LatencyLedger {
 public:
  /// An event on `input` was published at `t_s` (seconds on a monotonic clock).
  void begin_event(const std::string& input, double t_s);
  /// `process` acknowledged `handled` at `t_s`; ignored outside an event.
  void acknowledge(const std::string& process, const std::string& handled, double t_s);
  /// The event has settled: each process's last acknowledgement becomes its kAll sample.
  void end_event();

  static constexpr const char* kAll = "(all)";

  std::vector<LatencyRow> rows() const;

 private:
  using Key = std::tuple<std::string, std::string, std::string>;  // input, process, handled
  std::map<Key, LatencySamples> samples_ms_;
  std::string input_;
  double started_s_ = 0.0;
  bool in_event_ = false;
  std::set<std::pair<std::string, std::string>> seen_;  // this event's (process, handled)
  std::map<std::string, double> last_s_;                // this event's last ack per process
};

/// The nearest-rank quantile q in [0, 1] of `values` (sorted copy); NaN when empty.
double quantile(std::vector<double> values, double q);

/// The rows as a table under a heading line; "" when there are none.
std::string format_latency(const std::vector<LatencyRow>& rows);

}  // namespace kestrel::replay
