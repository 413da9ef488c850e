#pragma once
// How long each process took with each input event, measured by the lock-step driver: from
// the moment it published an event to the moment each process acknowledged an input of that
// event (the event itself or a message the event caused). A process acknowledges after its
// handler has returned, so the time includes what the handler published: the estimator's
// acknowledgement of a VO_UPDATE in a CAMERA_RGBD event is when the STATE that includes the
// frame was out, which is the onboard latency of a frame (frame arrival -> STATE).
//
// Wall-clock times, so they depend on the machine and its load (the recording does not); two
// LCM loopback hops (about 0.1 ms each) are in every figure. Within an event only the first
// acknowledgement per (process, handled channel) counts.
//
// Invariants: a row's quantiles are of at least one sample; rows are ordered by input channel,
// then by median.

#include <cstdint>
#include <map>
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

class LatencyLedger {
 public:
  /// An event on `input` was published at `t_s` (seconds on a monotonic clock).
  void begin_event(const std::string& input, double t_s);
  /// `process` acknowledged `handled` at `t_s`; ignored before any event.
  void acknowledge(const std::string& process, const std::string& handled, double t_s);

  std::vector<LatencyRow> rows() const;

 private:
  using Key = std::tuple<std::string, std::string, std::string>;  // input, process, handled
  std::map<Key, std::vector<double>> samples_ms_;
  std::string input_;
  double started_s_ = 0.0;
  bool in_event_ = false;
  std::map<std::pair<std::string, std::string>, bool> seen_;  // this event's first acks
};

/// The nearest-rank quantile q in [0, 1] of `values` (sorted copy); NaN when empty.
double quantile(std::vector<double> values, double q);

/// The rows as a table, one line each; "" when there are none.
std::string format_latency(const std::vector<LatencyRow>& rows);

}  // namespace kestrel::replay
